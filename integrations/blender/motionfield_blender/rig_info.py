"""What the panel says about the active armature: which bone is the root and
how the library maps the rig onto the model's (mf_rig_describe)."""

import numpy as np

from . import animation, convert

_cache = {}


def root_name(settings, obj):
    """The root bone: the settings' when set, else the one that carries the travel."""
    return settings.root_bone or animation.travel_root(obj).name


def rest_motion(mf, rig):
    """A one-frame motion of the rig at its rest pose, as the tasks read it."""
    J = len(rig.names)
    identity = np.tile(np.array([1.0, 0.0, 0.0, 0.0], dtype=np.float32), (1, J, 1))
    return mf.Motion.from_arrays(convert.from_rest_frames(rig, identity), rig.rest_frame_offsets()[:1], 30.0,
                                 joint_names=rig.names, parents=rig.parents, offsets=rig.offsets)


def describe(mf, obj, root, scale, rig_map, model):
    """(dict of mf_rig_describe, None) or (None, the reason), cached per
    armature, bone set, root, rig map and model."""
    key = (obj.name, tuple(b.name for b in obj.data.bones), root, scale, rig_map, id(model))
    if key not in _cache:
        try:
            rig = convert.Rig(obj, root, scale)
            kw = {"rig_map": rig_map} if rig_map else {}
            _cache[key] = (mf.describe_rig(rest_motion(mf, rig), model=model, **kw), None)
        except Exception as e:  # shown in the panel
            _cache[key] = (None, str(e))
    return _cache[key]


def summary(d):
    """One line: how many of the model's joints are mapped and how, the unit."""
    mapped = len(d["map"])
    how = {}
    for v in d["how"].values():
        how[v] = how.get(v, 0) + 1
    ways = ", ".join("%d by %s" % (n, w) for w, n in sorted(how.items()))
    return "%d of %d model joints mapped (%s)" % (mapped, len(d["model_joints"]), ways)
