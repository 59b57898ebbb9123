// The decoder of the prior through the Eigen runtime (prior/runtime/) and
// through libtorch (NemfModel::decode, autograd on the latents), at one
// thread: forward and forward + VJP times for a gap window (30 frames) and a
// full window (128), on the runtime's default backend, the BLAS and Eigen's
// kernels; the decoder's matrix-product FLOPs per evaluation, the machine's
// single-thread SGEMM rate (the runtime's kernels, Eigen's and the system
// BLAS's at 512 x 512 x 512, and the default backend's at the decoder's own
// hidden-layer shape), and the runtime's forward + VJP time against the floor
// FLOPs / the fastest 512^3 rate (issue 56: within 1.5x). Then the default solve's whole energy with its gradient with
// respect to the latents, libtorch's evaluate_energy() + backward against the
// Eigen runtime's (tasks/latent/runtime_energy.h), on a gap window (10 known
// frames, a 30-frame gap, the frame after it) and a 128-frame window with
// keys every 15 frames, cut from a motion the prior decodes from zero codes.
// Last, the two-stage in-betweener's forward pass (both stages) on a 128-frame
// window with keys every 15 frames, libtorch against the Eigen runtime
// (prior/runtime/inbetween_runtime.h), from the file next to the prior.
// Prints markdown tables; median of --reps evaluations, in the calling
// thread's CPU time unless --wall-clock.
#include <ATen/ATen.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/model/representation.h"
#include "prior/runtime/inbetween_runtime.h"
#include "prior/runtime/nemf_runtime.h"
#include "prior/util/command_line.h"
#include "prior/util/threads.h"
#include "tasks/reference/energies.h"
#include "tasks/latent/runtime_energy.h"
#include "tasks/latent/runtime_latent_energy.h"
#include "tasks/transformer/inbetweener_files.h"

namespace {

using mf::runtime::MatrixRXf;

// The calling thread's CPU time (the default) or the wall clock, in ms. At
// one thread every product runs on the calling thread (OpenBLAS's pool is
// kept at 1), so its CPU time is the work done, which a machine shared with
// other jobs stretches less than the wall clock.
bool g_wall_clock = false;

double now_ms() {
  if (g_wall_clock) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
  }
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

template <class F>
double median_ms(int reps, F&& f) {
  std::vector<double> t;
  for (int i = 0; i < 3; ++i) f();  // warm-up: workspaces sized, caches filled
  for (int i = 0; i < reps; ++i) {
    const double a = now_ms();
    f();
    t.push_back(now_ms() - a);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

MatrixRXf random_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937& rng) {
  std::normal_distribution<float> n;
  MatrixRXf m(rows, cols);
  for (Eigen::Index i = 0; i < m.size(); ++i) m.data()[i] = n(rng);
  return m;
}

// GFLOP/s of c = a * b^T ([m, k] x [k, n]) through the runtime's gemm on
// `backend`, b a weight (on the Kernels backend: packed once, in the warm-up).
double gemm_rate(mf::runtime::GemmBackend backend, int m, int k, int n, int reps) {
  std::mt19937 rng(1);
  const MatrixRXf a = random_matrix(m, k, rng);
  const mf::runtime::WeightMatrix b(random_matrix(n, k, rng));
  MatrixRXf c(m, n);
  const mf::runtime::GemmBackend before = mf::runtime::gemm_backend();
  mf::runtime::set_gemm_backend(backend);
  const double ms = median_ms(reps, [&] { mf::runtime::gemm(a, false, b, true, c, 0.0f); });
  mf::runtime::set_gemm_backend(before);
  return 2.0 * m * k * n / (ms * 1e6);
}

struct DecoderTimes {
  double forward_ms, forward_vjp_ms;
};

DecoderTimes runtime_times(const mf::runtime::NemfRuntime& rt, int S, int reps) {
  std::mt19937 rng(S);
  const Eigen::VectorXd frames = Eigen::VectorXd::LinSpaced(S, 0.0, rt.config().window - 1.0);
  const MatrixRXf z_l = random_matrix(rt.config().zl, 1, rng), z_g = random_matrix(rt.config().zg, 1, rng);
  const MatrixRXf g = random_matrix(S, rt.rig().num_joints() * 6, rng);
  mf::runtime::DecoderWorkspace ws;
  MatrixRXf out;
  Eigen::VectorXf g_zl, g_zg;
  DecoderTimes t;
  t.forward_ms = median_ms(reps, [&] { rt.decode(frames, z_l, z_g, &ws, &out); });
  t.forward_vjp_ms = median_ms(reps, [&] {
    rt.decode(frames, z_l, z_g, &ws, &out);
    rt.decode_vjp(&ws, g, &g_zl, &g_zg);
  });
  return t;
}

DecoderTimes torch_times(const mf::NemfModel& model, int S, int reps) {
  const mf::NemfConfig& c = model.config();
  const at::Tensor frames = at::linspace(0.0, c.window - 1.0, S, at::kDouble);
  const at::Tensor z_l = at::randn({1, c.zl}), z_g = at::randn({1, c.zg});
  const at::Tensor g = at::randn({1, S, model.rig().num_joints(), 3, 3});
  DecoderTimes t;
  t.forward_ms = median_ms(reps, [&] {
    at::NoGradGuard no_grad;
    model.decode(frames, z_l, z_g);
  });
  t.forward_vjp_ms = median_ms(reps, [&] {
    const at::Tensor zl = z_l.clone().requires_grad_(true), zg = z_g.clone().requires_grad_(true);
    (model.decode(frames, zl, zg) * g).sum().backward();
  });
  return t;
}

// The motion the prior decodes from zero codes over its whole window, its
// root path from the GMP: a source of windows as long as the model's.
mf::Motion decoded_motion(const mf::NemfModel& model) {
  at::NoGradGuard no_grad;
  const int W = model.config().window;
  const at::Tensor z_l = at::zeros({1, model.config().zl}), z_g = at::zeros({1, model.config().zg});
  const at::Tensor rotations = model.decode(at::arange(W, at::kFloat), z_l, z_g);
  const at::Tensor root = model.root_positions(rotations, model.predict_global(rotations));
  mf::Motion m = mf::Motion::identity(model.rig().skeleton, W, model.config().fps);
  mf::write_window(rotations, root, mf::GroundTransform{}, &m, 0);
  return m;
}

struct EnergyTimes {
  double torch_ms, runtime_ms;
};

// The default energy + its gradient at random codes on frames [0, length) of
// `motion` with full-pose keys at `keys`.
EnergyTimes energy_times(const mf::NemfModel& model, const mf::runtime::NemfRuntime& rt, const mf::Motion& motion,
                         const std::vector<int>& keys, int length, int reps) {
  const mf::WindowProblem problem =
      mf::make_window_problem(model.rig(), motion, 0, length, mf::MotionConstraints::full_pose(keys), keys.front());
  const mf::RuntimeWindowProblem rp = mf::to_runtime_problem(problem, rt.rig().num_joints());
  const mf::EnergyWeights weights;
  std::mt19937 rng(length);
  const MatrixRXf z_l = random_matrix(rt.config().zl, 1, rng), z_g = random_matrix(rt.config().zg, 1, rng);
  const at::Tensor t_zl = at::from_blob(const_cast<float*>(z_l.data()), {1, z_l.rows()}, at::kFloat).clone();
  const at::Tensor t_zg = at::from_blob(const_cast<float*>(z_g.data()), {1, z_g.rows()}, at::kFloat).clone();
  EnergyTimes t;
  t.torch_ms = median_ms(reps, [&] {
    const at::Tensor zl = t_zl.clone().requires_grad_(true), zg = t_zg.clone().requires_grad_(true);
    mf::evaluate_energy(model, problem, weights, zl, zg).total.backward();
  });
  mf::RuntimeEnergy energy(rt);
  const Eigen::VectorXf zl = z_l.col(0), zg = z_g.col(0);
  Eigen::VectorXf g_zl, g_zg;
  t.runtime_ms = median_ms(reps, [&] { energy.evaluate(rp, weights, zl, zg, &g_zl, &g_zg); });
  return t;
}

void print_energy_times(const mf::NemfModel& model, const mf::runtime::NemfRuntime& rt, int reps) {
  const mf::Motion motion = decoded_motion(model);
  std::vector<int> every_15;
  for (int f = 0; f < 128; f += 15) every_15.push_back(f);
  every_15.push_back(127);
  const struct {
    const char* name;
    std::vector<int> keys;
    int length;
  } windows[] = {{"gap 30 (41 frames)", {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 40}, 41},
                 {"keys every 15 (128 frames)", every_15, 128}};
  std::printf("\nThe default energy + gradient (rotation, position, root_orientation, root_translation; squared)\n\n"
              "| window | libtorch evaluate_energy + backward (ms) | Eigen runtime (ms) | speed-up |\n"
              "|---|---|---|---|\n");
  for (const auto& w : windows) {
    const EnergyTimes t = energy_times(model, rt, motion, w.keys, w.length, reps);
    std::printf("| %s | %.3f | %.3f | %.1fx |\n", w.name, t.torch_ms, t.runtime_ms, t.torch_ms / t.runtime_ms);
  }
}

// The two-stage in-betweener next to the prior on a random 128-frame window
// (its pose values random, full keys every 15 frames and at the last).
void print_two_stage_times(const std::string& prior_path, int reps) {
  const std::string path = mf::inbetweener_path_next_to(prior_path, mf::kTwoStageKind);
  const std::unique_ptr<mf::InbetweenModel> model = mf::load_inbetweener(path);
  model->set_requires_grad(false);
  const std::unique_ptr<const mf::runtime::InbetweenerRuntime> rt = mf::runtime::load_inbetweener_runtime(path);
  const int T = std::min(128, rt->window()), J = rt->rig().num_joints();
  std::mt19937 rng(T);
  mf::runtime::InbetweenWindow w;
  w.pose = random_matrix(T, rt->pose_size(), rng);
  w.known = MatrixRXf::Zero(T, J + 1);
  for (int t = 0; t < T; t += 15) w.known.row(t).setOnes();
  w.known.row(T - 1).setOnes();
  w.valid = Eigen::VectorXf::Ones(T);
  mf::InbetweenBatch batch;
  batch.pose = at::from_blob(w.pose.data(), {1, T, w.pose.cols()}, at::kFloat).clone();
  batch.known = at::from_blob(w.known.data(), {1, T, J + 1}, at::kFloat).clone();
  batch.valid = at::ones({1, T});
  const double torch_ms = median_ms(reps, [&] {
    at::NoGradGuard no_grad;
    model->forward(batch);
  });
  mf::runtime::InbetweenResult out;
  const double runtime_ms = median_ms(reps, [&] { rt->forward(w, &out); });
  std::printf("\nThe two-stage in-betweener's forward pass (context + detail), %d frames, keys every 15 (%s)\n\n"
              "| libtorch forward (ms) | Eigen runtime (ms) | speed-up |\n|---|---|---|\n"
              "| %.3f | %.3f | %.1fx |\n",
              T, path.c_str(), torch_ms, runtime_ms, torch_ms / runtime_ms);
}

int run(const std::string& model_path, int reps) {
  mf::set_compute_threads(1);
  const mf::NemfModel model = mf::load_nemf(model_path);
  const mf::runtime::NemfRuntime rt = mf::runtime::NemfRuntime::load(model_path);
  using mf::runtime::GemmBackend;
  const int W = rt.config().decoder_width;
  const GemmBackend shipped = mf::runtime::gemm_backend();
  const double kernels_rate = gemm_rate(GemmBackend::Kernels, 512, 512, 512, 20);
  const double eigen_rate = gemm_rate(GemmBackend::Eigen, 512, 512, 512, 20);
  const double blas_rate = gemm_rate(GemmBackend::Blas, 512, 512, 512, 20);
  const double best_rate = std::max({kernels_rate, eigen_rate, blas_rate});
  static const char* const kIsa[] = {"none: the BLAS", "AVX2 + FMA", "AVX-512"};
  std::printf("1 thread; BLAS: %s; the runtime's kernels: %s; model %s (%s); times: median %s\n\n",
              mf::describe_blas().c_str(), kIsa[static_cast<int>(mf::runtime::cpu_kernel_isa())], model_path.c_str(),
              rt.config().describe().c_str(), g_wall_clock ? "wall clock" : "CPU time of the calling thread");
  std::printf("SGEMM 512 x 512 x 512 (b a packed weight): the runtime's kernels %.1f GFLOP/s, Eigen %.1f GFLOP/s, "
              "BLAS %.1f GFLOP/s; the floor takes the fastest\n\n",
              kernels_rate, eigen_rate, blas_rate);
  std::printf("| S | GEMM MFLOP fwd + VJP | runtime fwd (ms) | runtime fwd + VJP (ms) | on the BLAS fwd + VJP (ms) "
              "| on Eigen's kernels fwd + VJP (ms) | libtorch fwd (ms) | libtorch fwd + bwd (ms) "
              "| floor at the 512^3 rate (ms) | runtime / floor | rate at [S, %d] x [%d, %d] (GFLOP/s) "
              "| floor at that rate (ms) | runtime / that floor |\n"
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|\n",
              W, W, W);
  for (int S : {30, 128}) {
    const double flops = static_cast<double>(rt.decoder().forward_flops(S) + rt.decoder().vjp_flops(S));
    const double shape_rate = gemm_rate(shipped, S, W, W, 200);
    const DecoderTimes r = runtime_times(rt, S, reps);
    mf::runtime::set_gemm_backend(GemmBackend::Blas);
    const DecoderTimes b = runtime_times(rt, S, reps);
    mf::runtime::set_gemm_backend(GemmBackend::Eigen);
    const DecoderTimes e = runtime_times(rt, S, reps);
    mf::runtime::set_gemm_backend(shipped);
    const DecoderTimes t = torch_times(model, S, reps);
    const double floor_ms = flops / (best_rate * 1e6), shape_floor_ms = flops / (shape_rate * 1e6);
    std::printf("| %d | %.2f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.2f | %.1f | %.3f | %.2f |\n", S,
                flops * 1e-6, r.forward_ms, r.forward_vjp_ms, b.forward_vjp_ms, e.forward_vjp_ms, t.forward_ms,
                t.forward_vjp_ms, floor_ms, r.forward_vjp_ms / floor_ms, shape_rate, shape_floor_ms,
                r.forward_vjp_ms / shape_floor_ms);
  }
  print_energy_times(model, rt, reps);
  print_two_stage_times(model_path, reps);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string model_path = mf::default_model_path();
  int reps = 200;
  CLI::App app{"Times the prior's decoder through the Eigen runtime and through libtorch at one thread, against "
               "its matrix-product floor (FLOPs / measured SGEMM rate), and the default solve's energy + gradient both "
               "ways, and the two-stage in-betweener's forward pass both ways.",
               "runtime-bench"};
  mf::cli::use_tool_defaults(app);
  app.add_option("--model", model_path, "the prior's model file (default: the shipped one)");
  app.add_flag("--wall-clock", g_wall_clock, "time by the wall clock instead of the thread's CPU time");
  app.add_option("--reps", reps, "timed evaluations per figure (the median is printed)")->check(mf::cli::at_least(1));
  return mf::cli::run(app, argc, argv, [&] { return run(model_path, reps); });
}
