"""Tests of the ctypes package (run by CTest through /usr/bin/python3):

    MOTIONFIELD_LIBRARY=build/capi/libmotionfield.so PYTHONPATH=python \\
        /usr/bin/python3 -m unittest discover -s python/tests -v

The model tests need a model file: $MF_TEST_MODEL (CTest writes a tiny random
one with mf_capi_tiny_model) and the bundled model (in the repository); they
fail without them, so that a broken set-up cannot pass by skipping.
"""

import base64
import json
import os
import struct
import sys
import tempfile
import threading
import unittest

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.environ.get("MF_SOURCE_DIR", os.path.normpath(os.path.join(HERE, "..", "..")))
SAMPLE = os.path.join(SOURCE, "samples", "walk_keyframes.bvh")


def mapped_libraries():
    with open("/proc/self/maps") as f:
        return {line.split()[-1] for line in f if "/" in line}


# Loaded before anything imports motionfield: the process has no libtorch of
# its own, and libmotionfield.so brings none.
TORCH_BEFORE_IMPORT = [p for p in mapped_libraries() if "libtorch" in os.path.basename(p)]

import motionfield as mf  # noqa: E402


def small_skeleton():
    names = ["Hips", "Spine", "Head", "UpperLeg_L", "Foot_L", "UpperLeg_R", "Foot_R"]
    parents = [-1, 0, 1, 0, 3, 0, 5]
    offsets = np.array([[0, 0, 0], [0, 0.2, 0], [0, 0.4, 0], [0.1, -0.05, 0], [0, -0.8, 0], [-0.1, -0.05, 0],
                        [0, -0.8, 0]], dtype=np.float32)
    return names, parents, offsets


def random_rotations(frames, joints, seed):
    rng = np.random.default_rng(seed)
    q = rng.normal(size=(frames, joints, 4)).astype(np.float32)
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    return q


class LibraryTest(unittest.TestCase):
    def test_loads_without_libtorch(self):
        self.assertEqual(TORCH_BEFORE_IMPORT, [])
        mf.version()  # the library is loaded
        self.assertTrue(any("libmotionfield" in os.path.basename(p) for p in mapped_libraries()))
        self.assertNotIn("torch", sys.modules)
        loaded = [p for p in mapped_libraries() if "libtorch" in os.path.basename(p) or "libc10" in os.path.basename(p)]
        self.assertEqual(loaded, [], "libmotionfield.so brings libtorch along")

    def test_versions(self):
        self.assertEqual(mf.abi_version(), 0)
        self.assertRegex(mf.version(), r"^\d+\.\d+\.\d+$")
        self.assertTrue(os.path.exists(mf.library_path()))
        if os.environ.get("MOTIONFIELD_LIBRARY"):
            self.assertEqual(mf.library_path(), os.environ["MOTIONFIELD_LIBRARY"])

    def test_every_exported_function_is_declared(self):
        from motionfield import _capi
        with open(os.path.join(SOURCE, "tests", "capi", "exported_symbols.txt")) as f:
            # The C functions (mf_*): not assimp's replaced assertion handler (prior/motion/assimp_assert.cc).
            names = [line.strip() for line in f if line.startswith("mf_")]
        self.assertGreater(len(names), 50)
        for name in names:
            f = getattr(_capi, name, None)
            self.assertIsNotNone(f, name)
            self.assertIsNotNone(f.argtypes, name)
            self.assertIsNotNone(f.restype if not name.endswith("_destroy") else True, name)

    def test_threads(self):
        mf.set_num_threads(1)
        self.assertEqual(mf.get_num_threads(), 1)
        with self.assertRaises(mf.InvalidArgumentError) as cm:
            mf.set_num_threads(0)
        self.assertEqual(cm.exception.status, 1)
        self.assertEqual(cm.exception.status_name, "MF_ERROR_INVALID_ARGUMENT")
        self.assertIsInstance(cm.exception, ValueError)

    def test_methods(self):
        names = {m.name: m for m in mf.methods()}
        self.assertIn("interp", names)
        self.assertIn("zerovel", names)
        self.assertTrue(names["interp"].completes and names["interp"].resamples)
        self.assertFalse(names["interp"].needs_model)
        # Like the CLI: the default model's best method (see test_same_as_cli.py).
        self.assertIn(mf.default_method(), names)
        self.assertTrue(names[mf.default_method()].needs_model)
        self.assertTrue(names[mf.default_method()].completes)


class MotionTest(unittest.TestCase):
    def test_bvh(self):
        m = mf.Motion.load_bvh(SAMPLE)
        self.assertEqual(m.frame_count, 61)
        self.assertEqual(m.joint_count, 21)
        self.assertEqual(m.fps, 30.0)
        self.assertAlmostEqual(m.frame_time, 0.0333333333, places=12)
        self.assertEqual(m.joint_names[0], "Hips")
        self.assertEqual(m.parents[0], -1)
        r = m.rotations
        self.assertEqual(r.shape, (61, 21, 4))
        self.assertEqual(r.dtype, np.float32)
        np.testing.assert_allclose(np.linalg.norm(r, axis=-1), 1.0, atol=1e-5)
        self.assertEqual(m.root_positions.shape, (61, 3))
        self.assertEqual(m.global_positions.shape, (61, 21, 3))
        self.assertEqual(m.offsets.shape, (21, 3))
        text = m.to_bvh_text()
        self.assertTrue(text.startswith("HIERARCHY\nROOT joint_Root"))
        back = mf.Motion.from_bvh_text(text)
        np.testing.assert_allclose(back.rotations, r, atol=1e-6)
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "out.bvh")
            m.save_bvh(path)
            with open(path) as f:
                self.assertEqual(f.read(), text)

    def test_gltf(self):
        m = mf.Motion.load_bvh(SAMPLE)  # centimetres: glTF is in metres

        def check(doc, buffer):
            self.assertEqual([n["name"] for n in doc["nodes"]], m.joint_names)
            np.testing.assert_allclose([n["translation"] for n in doc["nodes"]], m.offsets, atol=1e-6)
            channels = doc["animations"][0]["channels"]
            self.assertEqual(len(channels), m.joint_count + 1)

            def output(channel):
                accessor = doc["accessors"][doc["animations"][0]["samplers"][channel["sampler"]]["output"]]
                view = doc["bufferViews"][accessor["bufferView"]]
                return np.frombuffer(buffer, np.float32, view["byteLength"] // 4, view.get("byteOffset", 0))

            root = [c for c in channels if c["target"]["path"] == "translation"][0]
            np.testing.assert_allclose(output(root).reshape(-1, 3), m.root_positions, atol=1e-6)
            spine = [c for c in channels if c["target"] == {"node": 1, "path": "rotation"}][0]
            np.testing.assert_allclose(output(spine).reshape(-1, 4), m.rotations[:, 1, [1, 2, 3, 0]], atol=1e-6)

        with tempfile.TemporaryDirectory() as d:
            m.save_gltf(os.path.join(d, "a.glb"))
            with open(os.path.join(d, "a.glb"), "rb") as f:
                glb = f.read()
            self.assertEqual(glb, m.to_gltf_bytes())
            self.assertEqual(glb[:4], b"glTF")
            json_length = struct.unpack_from("<I", glb, 12)[0]
            check(json.loads(glb[20:20 + json_length]), glb[20 + json_length + 8:])
            m.save_gltf(os.path.join(d, "b.gltf"))
            with open(os.path.join(d, "b.gltf"), "rb") as f:
                text = f.read()
            self.assertEqual(text, m.to_gltf_bytes("gltf"))
            doc = json.loads(text)
            check(doc, base64.b64decode(doc["buffers"][0]["uri"].split(",", 1)[1]))
            m.save_gltf(os.path.join(d, "c.bin"), format="glb")
            with self.assertRaises(mf.InvalidArgumentError):
                m.save_gltf(os.path.join(d, "d.bvh"))
            with self.assertRaises(mf.InvalidArgumentError):
                m.to_gltf_bytes("obj")
            with self.assertRaises(mf.FileError):
                m.save_gltf(os.path.join(d, "no", "e.glb"))
            self.assertEqual(sorted(os.listdir(d)), ["a.glb", "b.gltf", "c.bin"])

    def test_load_any_format(self):
        m = mf.Motion.load_bvh(SAMPLE)
        self.assertEqual(mf.Motion.load(SAMPLE).frame_count, m.frame_count)
        with tempfile.TemporaryDirectory() as d:
            m.save_gltf(os.path.join(d, "a.glb"))
            os.rename(os.path.join(d, "a.glb"), os.path.join(d, "a.data"))  # told by its content
            g = mf.Motion.load(os.path.join(d, "a.data"))
            self.assertEqual(g.joint_names, m.joint_names)
            self.assertEqual(g.length_scale, 1.0)
            np.testing.assert_allclose(g.global_positions, m.global_positions, atol=1e-5)
            self.assertEqual(mf.Motion.load(os.path.join(d, "a.data"), fps=60, animation="motion").frame_count, 121)
            with self.assertRaisesRegex(mf.InvalidArgumentError, "there is no animation 1"):
                mf.Motion.load(os.path.join(d, "a.data"), animation=1)
            with self.assertRaisesRegex(mf.InvalidArgumentError, "not a valid FBX file"):
                mf.Motion.load(os.path.join(d, "a.data"), format="fbx")
            with self.assertRaises(mf.InvalidArgumentError):
                mf.Motion.load(os.path.join(d, "a.data"), format="obj")
            with self.assertRaises(mf.InvalidArgumentError):
                mf.Motion.load(os.path.join(d, "a.data"), animation=-1)
        # An FBX on which assimp's own check fails: an error, not an abort of this process.
        bad = os.path.join(SOURCE, "fuzz", "corpus", "fuzz_fbx", "regression-assimp-assert-curve-without-keys.fbx")
        with self.assertRaisesRegex(mf.InvalidArgumentError, "not a valid FBX file: assimp's check"):
            mf.Motion.load(bad)

    def test_arrays_round_trip(self):
        names, parents, offsets = small_skeleton()
        rot = random_rotations(12, 7, 1)
        root = np.linspace(0, 1, 36, dtype=np.float32).reshape(12, 3)
        m = mf.Motion.from_arrays(rot, root, 24.0, joint_names=names, parents=parents, offsets=offsets)
        np.testing.assert_array_equal(m.rotations, rot)
        np.testing.assert_array_equal(m.root_positions, root)
        np.testing.assert_array_equal(m.offsets, offsets)
        self.assertEqual(m.joint_names, names)
        self.assertEqual(list(m.parents), parents)
        self.assertEqual(m.fps, 24.0)
        like = mf.Motion.from_arrays(rot[:5], root[:5], 24.0, like=m)
        self.assertEqual(like.frame_count, 5)
        # float64 input is converted; non-contiguous input too.
        m2 = mf.Motion.from_arrays(rot.astype(np.float64)[::1], root.T.copy().T, 24.0, like=m)
        np.testing.assert_array_equal(m2.rotations, rot)

    def test_bad_input_raises_with_the_message(self):
        names, parents, offsets = small_skeleton()
        rot = random_rotations(4, 7, 2)
        root = np.zeros((4, 3), np.float32)
        bad = rot.copy()
        bad[1, 2, 0] = np.nan
        with self.assertRaisesRegex(mf.InvalidArgumentError, "not a finite non-zero quaternion"):
            mf.Motion.from_arrays(bad, root, 30.0, joint_names=names, parents=parents, offsets=offsets)
        with self.assertRaisesRegex(mf.InvalidArgumentError, "shape"):
            mf.Motion.from_arrays(rot[:, :, :3], root, 30.0, joint_names=names, parents=parents, offsets=offsets)
        with self.assertRaises(mf.FileError) as cm:
            mf.Motion.load_bvh("/nonexistent/walk.bvh")
        self.assertIsInstance(cm.exception, OSError)
        with self.assertRaisesRegex(mf.InvalidArgumentError, "<memory>:"):
            mf.Motion.from_bvh_text("HIERARCHY\nROOT a\n{\n OFFSET 0 0 zero\n}\n")
        with self.assertRaisesRegex(mf.ModelError, "not a motionfield model file"):
            mf.Model(SAMPLE)
        with self.assertRaisesRegex(mf.ModelError, "not a motionfield model file"):
            mf.Model.from_bytes(b"not a model at all")
        walk = mf.Motion.load_bvh(SAMPLE)
        with self.assertRaisesRegex(mf.InvalidArgumentError, "keyframe 61 is out of range"):
            mf.inbetween(walk, [0, 30, 61])
        with self.assertRaisesRegex(mf.InvalidArgumentError, "unknown method 'magic'"):
            mf.inbetween(walk, [0, 60], method="magic")
        # (Without model=, a method that needs one runs with the default model,
        # as in the CLI: see test_package.py.)
        walk.close()
        with self.assertRaisesRegex(mf.InvalidArgumentError, "closed"):
            walk.frame_count


class TaskTest(unittest.TestCase):
    def setUp(self):
        self.walk = mf.Motion.load_bvh(SAMPLE)

    def test_inbetween_keeps_keyframes(self):
        keys = [0, 20, 40, 60]
        out = mf.inbetween(self.walk, keys, method="interp")
        self.assertEqual(out.frame_count, 61)
        np.testing.assert_array_equal(out.rotations[keys], self.walk.rotations[keys])
        self.assertFalse(np.array_equal(out.rotations[10], self.walk.rotations[10]))
        self.assertEqual(out.frame_time, self.walk.frame_time)
        self.assertEqual(out.to_bvh_text().split("MOTION")[0], self.walk.to_bvh_text().split("MOTION")[0])

    def test_fill_and_resample(self):
        out = mf.fill(self.walk, 10, 40, method="zerovel")
        np.testing.assert_array_equal(out.root_positions[:10], self.walk.root_positions[:10])
        np.testing.assert_array_equal(out.root_positions[10:40], np.repeat(self.walk.root_positions[9:10], 30, 0))
        up = mf.resample(self.walk, 60.0, method="interp")
        self.assertEqual(up.frame_count, 121)
        self.assertEqual(up.fps, 60.0)
        np.testing.assert_array_equal(up.root_positions[::2], self.walk.root_positions)
        self.assertEqual(mf.resample_frame_count(61, 30.0, 23.3), (47, True))
        self.assertEqual(mf.resample_frame_count(61, 30.0, 60.0), (121, False))
        self.assertEqual(up.warnings, "")
        self.assertIn("rounded down to 47 frames", mf.resample(self.walk, 23.3, method="interp").warnings)
        self.assertIn("rounded down to 47 frames", mf.resample(self.walk, 23.3).warnings)

    def test_progress_and_cancel(self):
        seen = []
        mf.inbetween(self.walk, [0, 60], progress=lambda p: seen.append(p))
        self.assertGreaterEqual(len(seen), 1)
        self.assertIsInstance(seen[0], mf.Progress)
        with self.assertRaises(mf.CancelledError):
            mf.inbetween(self.walk, [0, 60], progress=lambda p: True)

        class Boom(Exception):
            pass

        def explode(p):
            raise Boom()

        with self.assertRaises(Boom):
            mf.inbetween(self.walk, [0, 60], progress=explode)
        token = mf.CancelToken()
        token.cancel()
        self.assertTrue(token.cancelled)
        with self.assertRaises(mf.CancelledError):
            mf.resample(self.walk, 60.0, cancel=token)
        token.reset()
        self.assertEqual(mf.resample(self.walk, 60.0, cancel=token).frame_count, 121)

    def test_threads_give_the_same_results(self):
        keys = [[0, 30, 60], [0, 10, 60], [0, 5, 20, 60]]  # the default method: nemf-detail
        sequential = [mf.inbetween(self.walk, k).rotations for k in keys]
        results = [None] * len(keys)

        def work(i):
            results[i] = mf.inbetween(self.walk, keys[i]).rotations

        threads = [threading.Thread(target=work, args=(i,)) for i in range(len(keys))]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for a, b in zip(sequential, results):
            np.testing.assert_array_equal(a, b)


class ModelTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not os.environ.get("MF_TEST_MODEL"):
            raise AssertionError("set MF_TEST_MODEL to a (tiny) model file (CTest does)")

    def test_model_and_codec(self):
        model = mf.Model(os.environ["MF_TEST_MODEL"])
        self.assertGreater(model.joint_count, 0)
        self.assertEqual(len(model.joint_names), model.joint_count)
        self.assertEqual(model.offsets.shape, (model.joint_count, 3))
        zl, zg = model.latent_sizes
        with open(os.environ["MF_TEST_MODEL"], "rb") as f:
            same = mf.Model.from_bytes(f.read())
        self.assertEqual(same.joint_names, model.joint_names)
        J = model.joint_count
        rot = random_rotations(40, J, 3)
        root = np.zeros((40, 3), np.float32)
        root[:, 1] = 0.9
        m = mf.Motion.from_arrays(rot, root, 30.0, model=model)
        code = mf.encode(m, model=model)
        self.assertEqual(code.local_latents.shape, (code.window_count, zl))
        self.assertEqual(code.global_latents.shape, (code.window_count, zg))
        self.assertAlmostEqual(code.duration, 39 / 30.0)
        dec = code.decode(60.0)
        self.assertEqual(dec.frame_count, 79)
        picked = code.decode_times([0.5, 0.0], 60.0)
        np.testing.assert_allclose(picked.rotations[0], dec.rotations[30], atol=1e-5)
        np.testing.assert_allclose(code.decode(30.0, root="input").root_positions, root, atol=1e-5)
        same_code = code.with_latents(code.local_latents, code.global_latents)
        np.testing.assert_array_equal(same_code.decode(60.0).rotations, dec.rotations)

    def test_fallback_to_interpolation_can_be_switched_off(self):
        model = mf.Model(os.environ["MF_TEST_MODEL"])  # a tiny random prior cannot reach random keys
        m = mf.Motion.from_arrays(random_rotations(26, model.joint_count, 9), np.zeros((26, 3), np.float32), 30.0,
                                  model=model)
        interp = mf.fill(m, 5, 20, method="interp")
        out = mf.fill(m, 5, 20, method="nemf", model=model)
        self.assertIn("interpolation was used", out.warnings)
        np.testing.assert_array_equal(out.rotations, interp.rotations)
        own = mf.fill(m, 5, 20, method="nemf", model=model, fallback=False)
        self.assertNotIn("interpolation was used", own.warnings)
        self.assertGreater(float(np.abs(own.rotations - interp.rotations).max()), 1e-3)
        solved = mf.solve(m, [f for f in range(26) if not 5 <= f < 20], method="nemf", model=model, fallback=False)
        np.testing.assert_array_equal(solved.motion.rotations, own.rotations)
        with self.assertRaises(TypeError):
            mf.fill(m, 5, 20, method="nemf", model=model, fallback="no")

    def test_max_iterations_budgets_the_solver(self):
        model = mf.Model(os.environ["MF_TEST_MODEL"])
        m = mf.Motion.from_arrays(random_rotations(30, model.joint_count, 5), np.zeros((30, 3), np.float32), 30.0,
                                  model=model)
        budgets = {}
        for budget in (0, 2):
            seen = []
            mf.inbetween(m, [0, 29], method="nemf", model=model, max_iterations=budget, progress=seen.append)
            budgets[budget] = max(p.max_iterations for p in seen)
            self.assertLessEqual(max(p.iteration for p in seen), budgets[budget])
        self.assertLess(budgets[2], budgets[0])
        # A clip longer than the model's window is solved window by window: progress says which.
        frames = model.window + 40
        long = mf.Motion.from_arrays(random_rotations(frames, model.joint_count, 6), np.zeros((frames, 3), np.float32),
                                     30.0, model=model)
        seen = []
        mf.inbetween(long, [0, frames // 2, frames - 1], method="nemf", model=model, max_iterations=1,
                     progress=seen.append)
        windows = sorted({(p.window, p.window_count) for p in seen if p.window_count})
        self.assertGreater(len(windows), 1)
        self.assertEqual(windows, [(w, len(windows)) for w in range(len(windows))])
        with self.assertRaisesRegex(mf.InvalidArgumentError, "max_iterations"):
            mf.inbetween(m, [0, 29], method="nemf", model=model, max_iterations=-1)

    def test_transformers_are_optional_and_named_when_missing(self):
        model = mf.Model(os.environ["MF_TEST_MODEL"])
        self.assertFalse(model.has_inbetweener("twostage"))
        self.assertFalse(model.has_inbetweener("citl"))
        with self.assertRaises(mf.InvalidArgumentError):
            model.has_inbetweener("lstm")
        with self.assertRaises(mf.FileError):
            model.with_inbetweener(os.path.join(os.path.dirname(os.environ["MF_TEST_MODEL"]), "absent.mfm"))
        with self.assertRaisesRegex(mf.ModelError, "wrong kind"):
            model.with_inbetweener(os.environ["MF_TEST_MODEL"])  # a prior, not a transformer
        names = {m.name: m for m in mf.methods()}
        for name in ("context", "detail", "citl", "nemf-context", "nemf-detail", "nemf-citl"):
            self.assertTrue(names[name].needs_model and names[name].completes, name)
        J = model.joint_count
        m = mf.Motion.from_arrays(random_rotations(20, J, 4), np.zeros((20, 3), np.float32), 30.0, model=model)
        with self.assertRaisesRegex(mf.ModelError, "motionfield-citl.mfm"):
            mf.inbetween(m, [0, 19], method="citl", model=model)



DEFAULT_MODEL = os.path.join(SOURCE, "models", "motionfield-prior.mfm")


def mixamo_sample_text():
    """The sample with Mixamo's joint names (everything else unchanged)."""
    with open(SAMPLE) as f:
        text = f.read()
    names = {"Hips": "Hips", "Spine": "Spine", "Chest": "Spine2", "Neck": "Neck", "Head": "Head"}
    for side, word in (("L", "Left"), ("R", "Right")):
        for ours, theirs in (("Shoulder", "Shoulder"), ("UpperArm", "Arm"), ("LowerArm", "ForeArm"), ("Hand", "Hand"),
                             ("UpperLeg", "UpLeg"), ("LowerLeg", "Leg"), ("Foot", "Foot"), ("Toes", "ToeBase")):
            names["%s_%s" % (ours, side)] = word + theirs
    for ours, theirs in names.items():
        text = text.replace("JOINT %s\n" % ours, "JOINT mixamorig:%s\n" % theirs)
    return text


class UnitsTest(unittest.TestCase):
    def test_units_are_detected_or_given(self):
        cm = mf.Motion.load_bvh(SAMPLE)
        self.assertEqual(cm.length_scale, 0.01)
        metres = mf.Motion.from_bvh_text(cm.to_bvh_text(length_scale=1.0))
        self.assertEqual(metres.length_scale, 1.0)
        np.testing.assert_allclose(metres.global_positions, cm.global_positions, atol=1e-5)
        self.assertIn("OFFSET 0.14 0 0", metres.to_bvh_text())  # written back in metres
        self.assertEqual(mf.Motion.load_bvh(SAMPLE, units="in").length_scale, 0.0254)
        self.assertEqual(mf.Motion.load_bvh(SAMPLE, units=0.02).length_scale, 0.02)
        self.assertEqual(mf.Motion.load_bvh(SAMPLE, units="auto").length_scale, 0.01)
        self.assertEqual(mf.Motion.load_bvh(SAMPLE, length_scale=0.01).length_scale, 0.01)
        with self.assertRaisesRegex(mf.InvalidArgumentError, "unknown length unit 'furlong'"):
            mf.Motion.load_bvh(SAMPLE, units="furlong")
        with self.assertRaises(mf.InvalidArgumentError):
            mf.Motion.load_bvh(SAMPLE, units="m", length_scale=1.0)


class OtherRigTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        if not os.path.exists(DEFAULT_MODEL):
            raise AssertionError(DEFAULT_MODEL + " is missing (it is in the repository)")
        cls.model = mf.Model(DEFAULT_MODEL)
        cls.method = "detail" if cls.model.has_inbetweener("twostage") else "nemf"
        cm = mf.Motion.from_bvh_text(mixamo_sample_text())
        cls.user = mf.Motion.from_bvh_text(cm.to_bvh_text(length_scale=1.0))  # in metres

    def test_describe_rig(self):
        d = mf.describe_rig(self.user, model=self.model)
        self.assertEqual(d["unit"], "m")
        self.assertTrue(d["unit_detected"])
        self.assertEqual(d["joints"], 21)
        self.assertEqual(d["map"]["mixamorig:LeftForeArm"], "LowerArm_L")
        self.assertEqual(d["how"]["LowerArm_L"], "name")
        self.assertEqual(d["unmapped_user_joints"], [])
        self.assertEqual(d["model_joints"], self.model.joint_names)
        self.assertTrue(d["retargeting"])
        self.assertEqual(d["anatomy"], "known frames")  # the sample's rest is no T or A pose
        given = mf.describe_rig(self.user, model=self.model, rig_map={"mixamorig:Spine2": "Chest"})
        self.assertEqual(given["how"]["Chest"], "map file")
        with self.assertRaisesRegex(mf.InvalidArgumentError, "rig map: not valid JSON"):
            mf.describe_rig(self.user, model=self.model, rig_map="{oops")

    def test_tasks_on_another_rig(self):
        keys = [0, 20, 40, 60]
        out = mf.inbetween(self.user, keys, method=self.method, model=self.model)
        self.assertEqual(out.joint_names, self.user.joint_names)
        self.assertEqual(out.length_scale, 1.0)
        self.assertTrue(np.isfinite(out.rotations).all())
        np.testing.assert_array_equal(out.rotations[keys], self.user.rotations[keys])
        np.testing.assert_array_equal(out.root_positions[keys], self.user.root_positions[keys])
        # The three forms of rig_map= give the same result.
        mapping = {"mixamorig:Spine2": "Chest"}
        by_dict = mf.fill(self.user, 10, 30, method=self.method, model=self.model, rig_map=mapping)
        by_text = mf.fill(self.user, 10, 30, method=self.method, model=self.model, rig_map=json.dumps(mapping))
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "map.json")
            with open(path, "w") as f:
                json.dump(mapping, f)
            by_file = mf.fill(self.user, 10, 30, method=self.method, model=self.model, rig_map=path)
            with open(path, "w") as f:
                json.dump({"mixamorig:Hips": "NoSuchJoint"}, f)
            with self.assertRaisesRegex(mf.InvalidArgumentError, "map.json: rig map: the model has no joint"):
                mf.fill(self.user, 10, 30, method=self.method, model=self.model, rig_map=path)
            with self.assertRaises(mf.FileError):
                mf.fill(self.user, 10, 30, method=self.method, model=self.model, rig_map=os.path.join(d, "none.json"))
        np.testing.assert_array_equal(by_dict.rotations, by_text.rotations)
        np.testing.assert_array_equal(by_dict.rotations, by_file.rotations)
        resampled = mf.resample(self.user, 60.0, method="prior", model=self.model, rig_map=mapping)
        self.assertEqual(resampled.frame_count, 121)
        self.assertEqual(resampled.joint_names, self.user.joint_names)


if __name__ == "__main__":
    unittest.main()
