// The Eigen runtime on its own: built and linked against mf_runtime only (no
// libtorch; the runtime_links_no_torch test checks this binary), it loads the
// shipped prior and evaluates it, and runs the shipped in-betweeners
// (inbetween_runtime.h). tests/runtime_equivalence_test.cc compares
// it with libtorch and its gradients with finite differences,
// tests/runtime_inbetween_equivalence_test.cc the in-betweeners.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "prior/motion/errors.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/kinematics.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/runtime/packed_gemm.h"
#include "prior/runtime/rotations.h"
#include "prior/util/binary_io.h"
#include "tests/resident_memory.h"
#include "tasks/latent/runtime_energy.h"

namespace mf::runtime {
namespace {

const NemfRuntime& shipped() {
  static const NemfRuntime model = NemfRuntime::load(std::string(MF_SOURCE_DIR) + "/models/motionfield-prior.mfm");
  return model;
}

MatrixRXf normal_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937& rng, float scale = 1.0f) {
  std::normal_distribution<float> n(0.0f, scale);
  MatrixRXf m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = n(rng);
  return m;
}

Eigen::VectorXf normal_vector(Eigen::Index n, std::mt19937& rng) {
  const MatrixRXf m = normal_matrix(n, 1, rng);
  return Eigen::Map<const Eigen::VectorXf>(m.data(), n);
}

// The decoder's VJP is linear in the output gradient, and a reused workspace
// gives the results of a fresh one (fractional frames across the window).
TEST(RuntimeStandalone, DecoderVjpIsLinearAndWorkspacesAreReusable) {
  const NemfRuntime& m = shipped();
  std::mt19937 rng(7);
  const int S = 30, J6 = m.rig().num_joints() * 6;
  Eigen::VectorXd frames(S);
  for (int s = 0; s < S; ++s) frames[s] = 3.0 + 4.1 * s;
  const Eigen::VectorXf z_l = normal_vector(m.config().zl, rng), z_g = normal_vector(m.config().zg, rng);
  const MatrixRXf g1 = normal_matrix(S, J6, rng), g2 = normal_matrix(S, J6, rng);
  DecoderWorkspace ws;
  MatrixRXf out, again;
  Eigen::VectorXf l1, g1_zg, l2, g2_zg, l12, g12_zg;
  m.decode(frames, z_l, z_g, &ws, &out);
  ASSERT_EQ(out.rows(), S);
  ASSERT_EQ(out.cols(), J6);
  m.decode_vjp(&ws, g1, &l1, &g1_zg);
  m.decode_vjp(&ws, g2, &l2, &g2_zg);
  m.decode_vjp(&ws, 2.0f * g1 - g2, &l12, &g12_zg);
  EXPECT_LT((l12 - (2.0f * l1 - l2)).cwiseAbs().maxCoeff(), 1e-4f * l12.cwiseAbs().maxCoeff());
  EXPECT_LT((g12_zg - (2.0f * g1_zg - g2_zg)).cwiseAbs().maxCoeff(), 1e-4f * g12_zg.cwiseAbs().maxCoeff());
  DecoderWorkspace fresh;
  m.decode(frames.head(7), z_l * 0.5f, z_g, &ws, &again);  // another size in between
  m.decode(frames, z_l, z_g, &ws, &again);
  EXPECT_EQ(again, out);
  m.decode(frames, z_l, z_g, &fresh, &again);
  EXPECT_EQ(again, out);
}

// The GMPs give finite outputs of the documented shape on inputs around their
// statistics, and the steering GMP is another network than the default one.
TEST(RuntimeStandalone, GmpsHaveTheirShapes) {
  const NemfRuntime& m = shipped();
  ASSERT_TRUE(m.has_steering_gmp());
  std::mt19937 rng(11);
  const int T = 40, C = m.rig().num_joints() * 3 + 6, outputs = 4 + m.rig().num_feet();
  MatrixRXf x = normal_matrix(T, C, rng, 0.5f);
  x = ((x.array().rowwise() * m.stats().gmp_in_std.array()).rowwise() + m.stats().gmp_in_mean.array()).matrix();
  GmpWorkspace ws;
  MatrixRXf def, steer, g_x;
  m.predict_global(x, GmpUse::Default, &ws, &def);
  m.predict_global(x, GmpUse::Steering, &ws, &steer);
  ASSERT_EQ(def.rows(), T);
  ASSERT_EQ(def.cols(), outputs);
  EXPECT_TRUE(def.allFinite());
  EXPECT_GT((def - steer).cwiseAbs().maxCoeff(), 1e-3f);
  m.predict_global_vjp(&ws, GmpUse::Steering, normal_matrix(T, outputs, rng), &g_x);
  EXPECT_EQ(g_x.rows(), T);
  EXPECT_EQ(g_x.cols(), C);
  EXPECT_TRUE(g_x.allFinite());
}

// The runtime's own kernels, for each instruction set this CPU runs, against
// Eigen's product: every row-block and panel tail, a depth over one pass,
// beta 0 (c's NaNs ignored), 1 and 0.5, b as is and transposed, and rows of a
// read at a stride shorter than their length (a convolution's overlapping
// rows).
TEST(RuntimeStandalone, OwnKernelsMatchEigensProducts) {
  std::vector<KernelIsa> isas;
  if (cpu_kernel_isa() == KernelIsa::Avx512) isas = {KernelIsa::Avx512, KernelIsa::Avx2};
  if (cpu_kernel_isa() == KernelIsa::Avx2) isas = {KernelIsa::Avx2};
  if (isas.empty()) GTEST_SKIP() << "this CPU has neither AVX2 + FMA nor AVX-512";
  std::mt19937 rng(5);
  int checked = 0;
  for (KernelIsa isa : isas)
    for (int rows : {1, 5, 6, 7, 12, 13, 30, 37})
      for (int n : {1, 15, 16, 17, 33, 64})
        for (int depth : {1, 9, 256, 300})
          for (bool transpose : {false, true})
            for (float beta : {0.0f, 1.0f, 0.5f}) {
              const MatrixRXf a = normal_matrix(rows, depth, rng);
              const MatrixRXf b = transpose ? normal_matrix(n, depth, rng) : normal_matrix(depth, n, rng);
              const MatrixRXf c0 = normal_matrix(rows, n, rng);
              const PackedOperand packed(b.data(), b.rows(), b.cols(), b.cols(), transpose, isa);
              MatrixRXf c = c0;
              if (beta == 0.0f) c.setConstant(std::numeric_limits<float>::quiet_NaN());
              packed_gemm(a.data(), rows, depth, packed, c.data(), n, beta);
              const MatrixRXf op_b = transpose ? MatrixRXf(b.transpose()) : b;
              const MatrixRXf expected = (beta == 0.0f ? MatrixRXf::Zero(rows, n) : MatrixRXf(beta * c0)) + a * op_b;
              ASSERT_LT((c - expected).cwiseAbs().maxCoeff(), 1e-4f * (1.0f + std::sqrt(float(depth))))
                  << "isa " << int(isa) << " rows " << rows << " n " << n << " depth " << depth << " transpose "
                  << transpose << " beta " << beta;
              ++checked;
            }
  EXPECT_EQ(checked, int(isas.size()) * 8 * 6 * 4 * 2 * 3);
  // Overlapping rows: row t of the virtual a is x[t .. t + 2] flattened.
  const MatrixRXf x = normal_matrix(20, 8, rng), w = normal_matrix(24, 16, rng);
  const PackedOperand packed(w.data(), 24, 16, 16, false, isas.front());
  MatrixRXf c(18, 16);
  packed_gemm(x.data(), 18, 8, packed, c.data(), 16, 0.0f);
  for (int t = 0; t < 18; ++t) {
    const Eigen::Map<const Eigen::RowVectorXf> row(x.data() + 8 * t, 24);
    EXPECT_LT((c.row(t) - row * w).cwiseAbs().maxCoeff(), 1e-4f) << t;
  }
}

// A weight's product runs on the kernels by default where the CPU has them,
// and agrees with the BLAS's; a weight changed after it was packed is packed
// again.
TEST(RuntimeStandalone, WeightProductsAgreeAcrossBackends) {
  std::mt19937 rng(6);
  const MatrixRXf a = normal_matrix(30, 40, rng);
  WeightMatrix w(normal_matrix(24, 40, rng));
  if (cpu_kernel_isa() != KernelIsa::None) {
    EXPECT_EQ(gemm_backend(), GemmBackend::Kernels);
  }
  MatrixRXf kernels(30, 24), blas(30, 24);
  gemm(a, false, w, true, kernels, 0.0f);
  set_gemm_backend(GemmBackend::Blas);
  gemm(a, false, w, true, blas, 0.0f);
  set_gemm_backend(GemmBackend::Kernels);
  EXPECT_LT((kernels - blas).cwiseAbs().maxCoeff(), 1e-4f);
  w.mutable_values().setZero();
  gemm(a, false, w, true, kernels, 0.0f);
  EXPECT_EQ(kernels.cwiseAbs().maxCoeff(), 0.0f);
}

// Convolutions and their input gradients on the kernels (one product over
// the stacked taps at stride 1) equal the per-tap products on the BLAS, at
// strides 1 and 2, for kernels of 1, 3 and 7 taps.
TEST(RuntimeStandalone, ConvolutionsOnTheKernelsMatchTheBlas) {
  if (cpu_kernel_isa() == KernelIsa::None) GTEST_SKIP() << "no kernels on this CPU";
  std::mt19937 rng(7);
  for (int K : {1, 3, 7})
    for (int stride : {1, 2}) {
      Conv1dWeights w;
      for (int k = 0; k < K; ++k) w.taps.emplace_back(normal_matrix(19, 23, rng));
      w.bias = normal_matrix(1, 23, rng);
      const MatrixRXf x = normal_matrix(40, 19, rng);
      MatrixRXf y[2];
      const int rows = conv1d_output_rows(40, K, stride);
      const MatrixRXf g_y = normal_matrix(rows, 23, rng);
      MatrixRXf g_x[2];
      for (int b = 0; b < 2; ++b) {
        set_gemm_backend(b == 0 ? GemmBackend::Kernels : GemmBackend::Blas);
        conv1d(x, w, stride, &y[b]);
        g_x[b] = MatrixRXf::Ones(40, 19);
        conv1d_input_gradient(g_y, w, stride, g_x[b]);
      }
      set_gemm_backend(GemmBackend::Kernels);
      ASSERT_EQ(y[0].rows(), rows);
      EXPECT_LT((y[0] - y[1]).cwiseAbs().maxCoeff(), 1e-4f) << K << " " << stride;
      EXPECT_LT((g_x[0] - g_x[1]).cwiseAbs().maxCoeff(), 1e-4f) << K << " " << stride;
    }
  // Inputs of the wrong width are refused, not read past.
  Conv1dWeights w;
  for (int k = 0; k < 7; ++k) w.taps.emplace_back(normal_matrix(19, 23, rng));
  w.bias = normal_matrix(1, 23, rng);
  MatrixRXf y, g_x = MatrixRXf::Zero(40, 18);
  EXPECT_THROW(conv1d(normal_matrix(40, 18, rng), w, 1, &y), std::logic_error);
  EXPECT_THROW(conv1d_input_gradient(normal_matrix(34, 23, rng), w, 1, g_x), std::logic_error);
}

// Both matrix-product backends (the system BLAS, Eigen's kernels) give the
// same products, transposed operands and strided blocks included.
TEST(RuntimeStandalone, GemmBackendsAgree) {
  std::mt19937 rng(3);
  const MatrixRXf a = normal_matrix(37, 53, rng), b = normal_matrix(29, 53, rng);
  const MatrixRXf c0 = normal_matrix(37, 29, rng);
  MatrixRXf blas = c0, eigen = c0;
  set_gemm_backend(GemmBackend::Blas);
  gemm(a, false, b, true, blas, 0.5f);
  set_gemm_backend(GemmBackend::Eigen);
  gemm(a, false, b, true, eigen, 0.5f);
  set_gemm_backend(GemmBackend::Kernels);
  const MatrixRXf expected = 0.5f * c0 + a * b.transpose();
  EXPECT_LT((blas - expected).cwiseAbs().maxCoeff(), 1e-4f);
  EXPECT_LT((eigen - expected).cwiseAbs().maxCoeff(), 1e-4f);
  MatrixRXf block_result(10, 29);
  gemm(a.block(2, 3, 10, 50).transpose(), true, b.middleCols(3, 50), true, block_result, 0.0f);
  EXPECT_LT((block_result - a.block(2, 3, 10, 50) * b.middleCols(3, 50).transpose()).cwiseAbs().maxCoeff(), 1e-4f);
}

// The latent energy without libtorch: full keys at what z0 decodes to give a
// near-zero energy and gradient at z0 and a larger energy away from it; the
// latent prior is 0.5 |z|^2 weighted; a dense term adds its own; an
// effector outside the window is refused.
TEST(RuntimeStandalone, LatentEnergyVanishesAtAPerfectFit) {
  const NemfRuntime& m = shipped();
  const int J = m.rig().num_joints();
  std::mt19937 rng(5);
  const Eigen::VectorXf z_l = normal_vector(m.config().zl, rng), z_g = normal_vector(m.config().zg, rng);
  RuntimeWindowProblem p;
  p.length = 31;
  p.key_frames = {0, 12, 30};
  DecoderWorkspace ws;
  MatrixRXf sixd, positions, globals;
  m.decode(Eigen::Vector3d(0.0, 12.0, 30.0), z_l, z_g, &ws, &sixd);
  sixd_to_matrix(sixd, &p.key_rotations);
  Kinematics(m.rig().skeleton).forward(p.key_rotations, MatrixRXf::Zero(3, 3), &positions, &globals);
  p.key_positions = positions;
  p.key_rotation_mask = p.key_position_mask = MatrixRXf::Ones(3, J);
  p.key_position_mask.col(0).setZero();
  p.key_root = MatrixRXf::Zero(3, 3);
  p.key_root_mask = Eigen::VectorXf::Zero(3);
  RuntimeEnergy energy(m);
  EnergyWeights w;
  Eigen::VectorXf g_zl, g_zg, far_zl, far_zg;
  const RuntimeEnergyTerms at_fit = energy.evaluate(p, w, z_l, z_g, &g_zl, &g_zg);
  ASSERT_EQ(at_fit.terms.size(), 3u);  // rotation, root_orientation, position
  const RuntimeEnergyTerms away = energy.evaluate(p, w, z_l * 0.5f, z_g, &far_zl, &far_zg);
  EXPECT_LT(at_fit.total, 1e-6);
  EXPECT_GT(away.total, 1e-2);
  EXPECT_LT(g_zl.norm() + g_zg.norm(), 1e-3f * (far_zl.norm() + far_zg.norm()));
  w.latent_prior = 2.0;
  const double with_prior = energy.evaluate(p, w, z_l, z_g, nullptr, nullptr).total;
  EXPECT_NEAR(with_prior - at_fit.total, z_l.squaredNorm() + z_g.squaredNorm(), 1e-3);
  w.smoothness = 1.0;  // a term on the dense decode: the whole window decoded
  const RuntimeEnergyTerms smooth = energy.evaluate(p, w, z_l, z_g, nullptr, nullptr);
  ASSERT_EQ(smooth.terms.size(), 5u);  // rotation, root_orientation, position, smoothness, latent_prior
  EXPECT_EQ(smooth.terms[3].first, "smoothness");
  EXPECT_GT(smooth.terms[3].second, 0.0);
  p.effector_frames = {p.length};  // outside the window
  p.effector_joints = {0};
  p.effector_targets = MatrixRXf::Zero(1, 3);
  p.effector_weights = Eigen::VectorXf::Ones(1);
  EXPECT_THROW(energy.evaluate(p, w, z_l, z_g, nullptr, nullptr), InputError);
}

TEST(RuntimeStandalone, RejectsWrongShapes) {
  const NemfRuntime& m = shipped();
  DecoderWorkspace ws;
  MatrixRXf out;
  Eigen::VectorXd frames = Eigen::VectorXd::LinSpaced(5, 0.0, 4.0);
  EXPECT_THROW(m.decode(frames, Eigen::VectorXf::Zero(3), Eigen::VectorXf::Zero(m.config().zg), &ws, &out),
               InputError);
  GmpWorkspace gw;
  EXPECT_THROW(m.predict_global(MatrixRXf::Zero(10, 5), GmpUse::Default, &gw, &out), InputError);
  const int J = m.rig().num_joints();
  EXPECT_THROW(m.encode_features(MatrixRXf::Zero(m.config().window + 1, J * 15), MatrixRXf::Zero(m.config().window + 1, 6),
                                 Eigen::VectorXf::Ones(m.config().window + 1)),
               InputError);
}

// Loading from a mapped file gives its pages back as the weights are copied:
// the process does not hold the weights twice, the file's bytes still read
// back unchanged, and the runtime is the one from_bytes() makes.
TEST(RuntimeStandalone, LoadingAFileDoesNotHoldItsWeightsTwice) {
  const std::string path = std::string(MF_SOURCE_DIR) + "/models/motionfield-prior.mfm";
  const std::vector<uint8_t> copy = [&] {
    const FileBytes f = read_file_bytes(path);
    return std::vector<uint8_t>(f.data(), f.data() + f.size());
  }();
  const FileBytes file = read_file_bytes(path);
  const long long mapped = test::resident_bytes();
  const NemfRuntime loaded = NemfRuntime::from_file(file, path);
  const long long after = test::resident_bytes();
  ASSERT_GT(mapped, 0);
#ifndef __SANITIZE_ADDRESS__  // ASan's quarantine keeps the loader's freed buffers resident
  EXPECT_LT(after - mapped, static_cast<long long>(file.size() / 4))
      << "KiB resident: " << mapped / 1024 << " -> " << after / 1024;
#endif
  ASSERT_EQ(file.size(), copy.size());
  EXPECT_EQ(std::memcmp(file.data(), copy.data(), copy.size()), 0);

  const NemfRuntime reference = NemfRuntime::from_bytes(copy.data(), copy.size(), path);
  std::mt19937 rng(5);
  const Eigen::VectorXf z_l = normal_vector(loaded.config().zl, rng), z_g = normal_vector(loaded.config().zg, rng);
  const Eigen::VectorXd frames = Eigen::VectorXd::LinSpaced(30, 0.0, 29.0);
  DecoderWorkspace ws;
  MatrixRXf a, b;
  loaded.decode(frames, z_l, z_g, &ws, &a);
  reference.decode(frames, z_l, z_g, &ws, &b);
  EXPECT_EQ(a, b);
}

// Releasing bytes outside a mapped file, or of a file read into memory, does nothing.
TEST(RuntimeStandalone, ReleasingForeignBytesDoesNothing) {
  const FileBytes file = read_file_bytes(std::string(MF_SOURCE_DIR) + "/models/motionfield-rig.json");
  const std::vector<uint8_t> copy(file.data(), file.data() + file.size());
  std::vector<uint8_t> other(1 << 16, 7);
  file.release(other.data(), other.size());
  file.release(file.data() + 1, file.size());  // runs past the end
  EXPECT_EQ(std::vector<uint8_t>(file.data(), file.data() + file.size()), copy);
  EXPECT_TRUE(std::all_of(other.begin(), other.end(), [](uint8_t v) { return v == 7; }));
}

TEST(RuntimeStandalone, RefusesAFileWithoutItsWeights) {
  const std::string bytes = "MFMODEL";
  EXPECT_THROW(NemfRuntime::from_bytes(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), "x.mfm"),
               InputError);
}

// The checksum, computed beside the parse, still decides what a corrupted
// file is called: a flipped byte anywhere in the payload (a weight made
// NaN, a hyperparameter's name, the rig) says "checksum mismatch", as the
// in-line check did; the intact bytes load.
TEST(RuntimeStandalone, ACorruptedFileIsCalledCorrupted) {
  const FileBytes file = read_file_bytes(std::string(MF_SOURCE_DIR) + "/models/motionfield-prior.mfm");
  const std::vector<uint8_t> intact(file.data(), file.data() + file.size());
  EXPECT_NO_THROW(NemfRuntime::from_bytes(intact.data(), intact.size(), "prior.mfm"));
  const size_t n = intact.size();
  for (size_t at : {size_t{40}, size_t{400}, n / 3, n / 2, n - 100}) {
    for (uint8_t flip : {uint8_t{0x5a}, uint8_t{0xff}}) {
      std::vector<uint8_t> b = intact;
      b[at] ^= flip;
      try {
        NemfRuntime::from_bytes(b.data(), b.size(), "prior.mfm");
        ADD_FAILURE() << "byte " << at << " flipped loaded";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("corrupted model file (checksum mismatch)"), std::string::npos)
            << "byte " << at << ": " << e.what();
      }
    }
  }
  std::vector<uint8_t> b = intact;
  b[8] = 99;  // the format version: refused before any checksum
  try {
    NemfRuntime::from_bytes(b.data(), b.size(), "prior.mfm");
    ADD_FAILURE() << "version 99 loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unsupported model format version 99"), std::string::npos) << e.what();
  }
}

// Every shipped in-betweener loads and fills a window (5 context frames and
// the target known): its stages [T, D], finite; CITL exact on the known values.
TEST(RuntimeStandalone, InbetweenersFillAWindow) {
  for (const char* file : {"motionfield-twostage.mfm", "motionfield-citl.mfm", "motionfield-keyframe.mfm"}) {
    const auto model = load_inbetweener_runtime(std::string(MF_SOURCE_DIR) + "/models/" + file);
    const int T = std::min(40, model->window()), J = model->rig().num_joints(), D = model->pose_size();
    std::mt19937 rng(3);
    InbetweenWindow w;
    w.pose = normal_matrix(T, D, rng);
    w.known = MatrixRXf::Zero(T, J + 1);
    w.known.topRows(5).setOnes();
    w.known.row(T - 1).setOnes();
    w.valid = Eigen::VectorXf::Ones(T);
    InbetweenResult out;
    model->forward(w, &out);
    ASSERT_EQ(out.stages.size(), model->stage_names().size()) << file;
    for (const MatrixRXf& stage : out.stages) {
      EXPECT_EQ(stage.rows(), T);
      EXPECT_EQ(stage.cols(), D);
      EXPECT_TRUE(stage.allFinite()) << file;
    }
    if (model->kind() == "citl") {
      EXPECT_EQ(out.stages[0].topRows(5), w.pose.topRows(5));
      EXPECT_EQ(out.stages[0].row(T - 1), w.pose.row(T - 1));
    } else {
      EXPECT_EQ(out.contact_logits.rows(), T) << file;
      EXPECT_EQ(out.contact_logits.cols(), model->rig().num_feet()) << file;
    }
  }
}

}  // namespace
}  // namespace mf::runtime
