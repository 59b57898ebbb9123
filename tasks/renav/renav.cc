#include "tasks/renav/renav.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <memory>
#include <random>
#include <sstream>

#include "prior/runtime/nemf_runtime.h"
#include "prior/motion/errors.h"
#include "prior/motion/interpolation.h"
#include "prior/motion/rotations.h"
#include "prior/runtime/local_features.h"
#include "tasks/constraints/interpolation_fill.h"
#include "tasks/context/model_rig.h"
#include "tasks/latent/initializers.h"
#include "tasks/latent/latent_optimizer.h"
#include "tasks/latent/runtime_latent_energy.h"
#include "tasks/latent/windows.h"
#include "tasks/renav/renav_runtime_energy.h"

namespace mf {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

constexpr double kPi = 3.14159265358979323846;

double wrap_angle(double a) {
  a = std::fmod(a + kPi, 2.0 * kPi);
  if (a < 0) a += 2.0 * kPi;
  return a - kPi;
}

Eigen::Matrix3d rot_y(double yaw) { return Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix(); }

double heading_yaw(const Eigen::Quaterniond& root, const Eigen::Vector3d& forward, double fallback = 0.0) {
  const Eigen::Vector3d f = root.normalized() * forward;
  if (f.x() * f.x() + f.z() * f.z() < 1e-12) return fallback;
  return std::atan2(f.x(), f.z());
}

int default_iterations(LatentOptimizer s) { return s == LatentOptimizer::Adam ? 600 : 100; }

}  // namespace

// ---------------------------------------------------------------- the window

namespace {

void check_window_arguments(const runtime::NemfRuntime& model, const Motion& reference, int ref_begin, int ref_length,
                            int N, int begin, int length, const Motion* previous, int shared) {
  const int W = model.config().window;
  check_model_skeleton(model.rig(), reference.skeleton, "reference");
  if (ref_begin < 0 || ref_length < 2 || ref_begin + ref_length > reference.num_frames())
    throw InputError("reference segment [" + std::to_string(ref_begin) + ", " + std::to_string(ref_begin + ref_length) +
                     ") does not fit the reference (" + std::to_string(reference.num_frames()) + " frames, at least 2)");
  if (ref_length > W) throw InputError("a reference segment may have at most the model's window of frames");
  if (begin < 0 || length < 2 || length > W || begin + length > N)
    throw InputError("window [" + std::to_string(begin) + ", " + std::to_string(begin + length) +
                     ") does not fit the path (" + std::to_string(N) + " points, 2 to " + std::to_string(W) +
                     " frames per window)");
  if (shared < 0 || shared >= length || (shared > 0 && !previous))
    throw InputError("bad number of frames shared with the previous window");
  if (previous && shared > 0 &&
      (previous->num_joints() != model.rig().num_joints() || begin + shared > previous->num_frames()))
    throw InputError("the previous solution does not cover the shared frames");
}

// The reference segment's heading and travel direction (yaw) per frame.
struct ReferenceCourse {
  std::vector<double> heading, travel;
};

ReferenceCourse reference_course(const Motion& seg, const Eigen::Vector3d& forward) {
  const int R = seg.num_frames();
  ReferenceCourse c;
  c.heading.resize(R);
  std::vector<Eigen::Vector2d> xz(R);
  for (int f = 0; f < R; ++f) {
    c.heading[f] = heading_yaw(seg.rotation(f, 0), forward);
    xz[f] = Eigen::Vector2d(seg.root_positions[f].x(), seg.root_positions[f].z());
  }
  c.travel = tangent_yaws(xz, c.heading);
  return c;
}

// Heading-frame joint positions [T, J * 3] of canonical local rotations [T, J * 9].
runtime::MatrixRXf heading_frame_joints(const RigInfo& rig, const runtime::MatrixRXf& local_rotations) {
  runtime::MatrixRXf positions, globals;
  runtime::heading_free_positions(runtime::Kinematics(rig.skeleton), local_rotations, rig.root_forward.cast<float>(),
                                  &positions, &globals);
  return positions;
}

// The reference's signals of the energy: heading-frame joint positions and c(t).
void set_reference_signals(const RigInfo& rig, const Motion& seg, const ReferenceCourse& course, RenavWindow* w) {
  const int R = seg.num_frames();
  w->reference_joints = heading_frame_joints(rig, window_matrices(seg, 0, R, rig, 0).local_rotations);
  w->reference_heading.resize(R, 1);
  for (int f = 0; f < R; ++f)
    w->reference_heading(f, 0) = static_cast<float>(std::cos(course.heading[f] - course.travel[f]));
}

// The target path of the window and its tangents, in the canonical frame `transform`.
void set_target_signals(const std::vector<Eigen::Vector2d>& path, const std::vector<double>& target_yaw, int begin,
                        int length, RenavWindow* w) {
  const double yaw = w->transform.yaw;
  const Eigen::Matrix3d unturn = rot_y(-yaw);
  w->target_xz.resize(length, 2);
  w->target_tangent.resize(length, 2);
  for (int f = 0; f < length; ++f) {
    const Eigen::Vector2d& p = path[begin + f];
    const Eigen::Vector3d c = unturn * Eigen::Vector3d(p.x() - w->transform.x, 0.0, p.y() - w->transform.z);
    w->target_xz.row(f) << static_cast<float>(c.x()), static_cast<float>(c.z());
    const double a = target_yaw[begin + f] - yaw;
    w->target_tangent.row(f) << static_cast<float>(std::sin(a)), static_cast<float>(std::cos(a));
  }
}

// The reference turned to follow the target: each frame's root turned about +Y
// by (target travel - reference travel), placed on the path with the
// reference's height; then one rigid ground motion so that frame 0 sits at the
// canonical origin with the canonical heading.
Motion turned_reference(const Motion& seg, const ReferenceCourse& course, const std::vector<Eigen::Vector2d>& path,
                        const std::vector<double>& target_yaw, int begin, int length, const GroundTransform& canonical,
                        const Eigen::Vector3d& forward) {
  const int Tt = std::min(seg.num_frames(), length);
  Motion turned = seg.slice(0, Tt);
  for (int f = 0; f < Tt; ++f) {
    const double delta = target_yaw[begin + f] - course.travel[f];
    turned.rotation(f, 0) = (Eigen::Quaterniond(Eigen::AngleAxisd(delta, Eigen::Vector3d::UnitY())) *
                             seg.rotation(f, 0).normalized())
                                .normalized();
    turned.root_positions[f] = Eigen::Vector3d(path[begin + f].x(), seg.root_positions[f].y(), path[begin + f].y());
  }
  const double fix = wrap_angle(canonical.yaw - heading_yaw(turned.rotation(0, 0), forward));
  const Eigen::Quaterniond q(Eigen::AngleAxisd(fix, Eigen::Vector3d::UnitY()));
  const Eigen::Vector3d pivot(path[begin].x(), 0.0, path[begin].y());
  const Eigen::Vector3d target(canonical.x, 0.0, canonical.z);
  for (int f = 0; f < Tt; ++f) {
    turned.rotation(f, 0) = (q * turned.rotation(f, 0)).normalized();
    const Eigen::Vector3d p = turned.root_positions[f];
    const Eigen::Vector3d g = q * Eigen::Vector3d(p.x() - pivot.x(), 0.0, p.z() - pivot.z());
    turned.root_positions[f] = Eigen::Vector3d(g.x() + target.x(), p.y(), g.z() + target.z());
  }
  return turned;
}

// Continuity with the previous solution on the `shared` frames from `begin`:
// its local rotations (root in the window's canonical frame) and heading-frame
// joint positions there.
void set_shared_frames(const RigInfo& rig, const Motion& previous, int begin, int shared, RenavWindow* w) {
  const int J = rig.num_joints();
  const Eigen::Matrix3d unturn = rot_y(-w->transform.yaw);
  w->shared_rotations.resize(shared, J * 9);
  for (int f = 0; f < shared; ++f) {
    for (int j = 0; j < J; ++j) {
      Eigen::Matrix3d m = previous.rotation(begin + f, j).normalized().toRotationMatrix();
      if (j == 0) m = unturn * m;
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) w->shared_rotations(f, j * 9 + a * 3 + b) = static_cast<float>(m(a, b));
    }
  }
  w->shared_joints = heading_frame_joints(rig, w->shared_rotations);
}

}  // namespace

RenavWindow make_renav_window(const runtime::NemfRuntime& model, const Motion& reference, int ref_begin, int ref_length,
                              const std::vector<Eigen::Vector2d>& path, int begin, int length, const Motion* previous,
                              int shared) {
  check_window_arguments(model, reference, ref_begin, ref_length, static_cast<int>(path.size()), begin, length,
                         previous, shared);
  const RigInfo& rig = model.rig();
  const Eigen::Vector3d fwd = rig.root_forward;
  RenavWindow w;
  w.length = length;
  Motion seg = reference.slice(ref_begin, ref_begin + ref_length);
  const ReferenceCourse course = reference_course(seg, fwd);
  set_reference_signals(rig, seg, course, &w);
  // The target's tangents over the whole path (context beyond the window's ends).
  const std::vector<double> target_yaw = tangent_yaws(path);

  // The canonical frame: at the previous solution where it continues one, else
  // on the path heading along it with the reference's facing offset.
  if (previous && shared > 0) {
    const Eigen::Vector3d& r = previous->root_positions[begin];
    w.transform.x = r.x();
    w.transform.z = r.z();
    w.transform.yaw = heading_yaw(previous->rotation(begin, 0), fwd, target_yaw[begin]);
  } else {
    w.transform.x = path[begin].x();
    w.transform.z = path[begin].y();
    w.transform.yaw = wrap_angle(target_yaw[begin] + (course.heading[0] - course.travel[0]));
  }
  set_target_signals(path, target_yaw, begin, length, &w);
  w.turned_segment = turned_reference(seg, course, path, target_yaw, begin, length, w.transform, fwd);
  w.reference_segment = std::move(seg);
  if (previous && shared > 0) set_shared_frames(rig, *previous, begin, shared, &w);
  return w;
}

// ---------------------------------------------------------------- solvers

namespace {

const std::vector<std::string>& init_names() {
  static const std::vector<std::string> names{"turned", "reference", "random"};
  return names;
}

}  // namespace

// ---------------------------------------------------------------- the solve

std::string RenavOptions::validate() const {
  std::ostringstream e;
  e << LatentOptimizerSettings::validate();
  if (overlap < 0) e << "overlap must be >= 0; ";
  const RenavWeights& w = weights;
  for (double v : {w.path, w.joints, w.heading, w.foot_skating, w.continuity}) {
    if (!(v >= 0) || !std::isfinite(v)) {
      e << "energy weights must be finite and non-negative; ";
      break;
    }
  }
  if (!(w.gamma > 0) || !std::isfinite(w.gamma)) e << "gamma must be finite and positive; ";
  for (const std::string& n : inits) {
    if (std::find(init_names().begin(), init_names().end(), n) == init_names().end())
      e << "unknown initialisation '" << n << "' (turned, reference, random); ";
  }
  return e.str();
}

RenavOptions default_renav_options(LatentOptimizer optimizer) {
  RenavOptions o;
  o.optimizer = optimizer;
  return o;
}

namespace {

void check_renav_input(const runtime::NemfRuntime& model, const Motion& reference,
                       const std::vector<Eigen::Vector2d>& path, double path_fps, const RenavOptions& options) {
  const std::string bad = options.validate();
  if (!bad.empty()) throw InputError("invalid re-navigation options: " + bad);
  check_model_skeleton(model.rig(), reference.skeleton, "reference");
  if (reference.num_frames() < 2) throw InputError("the reference needs at least two frames");
  reference.validate();
  validate_path(path);
  if (!(std::isfinite(path_fps) && path_fps > 0)) throw InputError("the path's frame rate must be finite and positive");
}

// The reference at the model's rate `fm` (interpolated over its time span).
Motion reference_at_model_rate(const Motion& reference, double fm) {
  Motion ref_m = reference;
  if (!same_frame_rate(reference.fps, fm)) {
    const int frames = static_cast<int>(std::floor((reference.num_frames() - 1) * fm / reference.fps + 1e-6)) + 1;
    if (frames < 2) {
      std::ostringstream msg;
      msg << "the reference is too short: it needs at least two frames at the model's " << fm << " fps";
      throw InputError(msg.str());
    }
    ref_m = resample_interpolate(reference, fm, frames);
  }
  ref_m.fps = fm;
  return ref_m;
}

}  // namespace

double reference_pace(const Motion& reference, const std::vector<Eigen::Vector2d>& path, double path_fps) {
  const int N = static_cast<int>(path.size());
  const double speed = mean_ground_speed(reference);
  if (N < 2 || !(path_fps > 0) || !std::isfinite(speed) || speed < 0.05) return 1.0;
  double length = 0.0;
  for (int i = 1; i < N; ++i) length += (path[i] - path[i - 1]).norm();
  const double ratio = length / ((N - 1) / path_fps) / speed;
  if (!std::isfinite(ratio) || std::abs(ratio - 1.0) <= 0.05) return 1.0;
  return std::clamp(ratio, kMinPace, kMaxPace);
}

namespace {

// The path (points at `path_fps`) at the model's rate `fm`: linear in time,
// the last point at or past the path's end time.
std::vector<Eigen::Vector2d> path_at_model_rate(const std::vector<Eigen::Vector2d>& path, double path_fps, double fm) {
  if (same_frame_rate(path_fps, fm)) return path;
  const int N = static_cast<int>(path.size());
  const double span = (N - 1) * fm / path_fps;
  const int M = static_cast<int>(std::ceil(span - 1e-6)) + 1;
  if (M > kMaxPathFrames) throw InputError("the path is too long at the model's frame rate");
  std::vector<Eigen::Vector2d> path_m(std::max(2, M));
  for (int i = 0; i < static_cast<int>(path_m.size()); ++i) {
    const double u = std::min<double>(N - 1, i * path_fps / fm);
    const int a = std::min(N - 2, static_cast<int>(std::floor(u)));
    const double t = u - a;
    path_m[i] = path[a] * (1.0 - t) + path[a + 1] * t;
  }
  return path_m;
}

// One window (model rate; its shared frames are its first, shared with the
// window before) and the reference segment it is compared with.
struct RenavSpan : WindowSpan {
  int ref_begin = 0, ref_length = 0;
};

// The windows of an M-frame path with an R-frame reference (see the header:
// the same reference frames when the reference is as long, else segments
// spread evenly over it).
std::vector<RenavSpan> renav_spans(int M, int R, int W, int overlap) {
  const std::vector<int> starts = window_starts(M, W, W - overlap);
  std::vector<RenavSpan> spans;
  for (size_t k = 0; k < starts.size(); ++k) {
    RenavSpan w;
    w.start = starts[k];
    w.length = std::min(W, M - w.start);
    w.ref_length = std::min(R, w.length);
    if (R >= M) {
      w.ref_begin = w.start;  // time-aligned
    } else if (R > w.length && M > w.length) {
      w.ref_begin = static_cast<int>(std::lround(static_cast<double>(w.start) * (R - w.length) / (M - w.length)));
    }
    w.ref_begin = std::clamp(w.ref_begin, 0, R - w.ref_length);
    w.shared_end = k > 0 ? std::max(0, starts[k - 1] + std::min(W, M - starts[k - 1]) - w.start) : 0;
    spans.push_back(w);
  }
  return spans;
}

// The energy of one window on the Eigen runtime (which the solve minimises
// and decodes with).
struct RenavWindowEnergies {
  RenavWindowEnergies(const runtime::NemfRuntime& model, const RenavWindow& window, const RenavOptions& options)
      : evaluator(model, window, options.weights),
        direct(
            [e = &evaluator](const Eigen::Ref<const Eigen::VectorXf>& z_l, const Eigen::Ref<const Eigen::VectorXf>& z_g,
                             Eigen::VectorXf* g_zl,
                             Eigen::VectorXf* g_zg) { return e->evaluate(z_l, z_g, g_zl, g_zg); },
            model.config().zl, model.config().zg) {}

  DirectLatentEnergy& energy() { return direct; }

  RenavRuntimeEnergy evaluator;
  RuntimeLatentEnergy direct;
};

// The initial codes of window `k`: z_l from the reference segment, z_g from
// each candidate of `inits`; the lowest energy is kept (recorded in *sum).
Eigen::VectorXd initial_codes(const runtime::NemfRuntime& model, const RenavWindow& window, RenavWindowEnergies& energy,
                              const std::vector<std::string>& inits, uint64_t seed, int k, RenavWindowSummary* sum) {
  const int zg = model.config().zg;
  const InitialGuess ref_code = encode_window(model, window.reference_segment, 0);
  Eigen::VectorXd x0;
  double best = std::numeric_limits<double>::infinity();
  for (const std::string& name : inits) {
    Eigen::VectorXf z_g(zg);
    if (name == "turned") {
      z_g = encode_window(model, window.turned_segment, 0).z_g;
    } else if (name == "reference") {
      z_g = ref_code.z_g;
    } else {
      std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + static_cast<uint64_t>(k));
      std::normal_distribution<float> normal(0.0f, 1.0f);
      for (int i = 0; i < zg; ++i) z_g[i] = normal(rng);
    }
    const Eigen::VectorXd x = join_codes(ref_code.z_l, z_g);
    const double e = energy.energy().evaluate(x.data(), nullptr);
    sum->init_energies.emplace_back(name, e);
    if (e < best || x0.size() == 0) {
      best = e;
      x0 = x;
      sum->init = name;
    }
  }
  return x0;
}

// The window decoded at the solution x.
DecodedWindow decode_solution(const runtime::NemfRuntime& model, RenavWindowEnergies& energy,
                              const Eigen::VectorXd& x) {
  const Eigen::VectorXf z_l = head_codes(x, model.config().zl), z_g = tail_codes(x, model.config().zg);
  DecodedWindow d;
  energy.evaluator.decode_window(z_l, z_g, &d.local_rotations, &d.root_positions, &d.contacts);
  return d;
}

// Mean and maximum horizontal distance of the output's root from the path, cm.
void measure_path_error(const Motion& result, const std::vector<Eigen::Vector2d>& path, RenavReport* rep) {
  const int N = static_cast<int>(path.size());
  double err_sum = 0.0;
  for (int f = 0; f < N; ++f) {
    const Eigen::Vector3d& r = result.root_positions[f];
    const double e = std::hypot(r.x() - path[f].x(), r.z() - path[f].y()) * 100.0;
    err_sum += e;
    rep->path_error_max_cm = std::max(rep->path_error_max_cm, e);
  }
  rep->path_error_mean_cm = err_sum / N;
}

// Re-navigation at the model's rate: the reference played at the path's pace,
// the path, the windows and the iteration cap of each.
struct RenavPlan {
  double pace = 1.0;
  Motion reference;
  std::vector<Eigen::Vector2d> path;
  std::vector<RenavSpan> spans;
  int cap = 0;
};

RenavPlan plan_renav(const runtime::NemfRuntime& model, const Motion& reference,
                     const std::vector<Eigen::Vector2d>& path, double path_fps, const RenavOptions& options) {
  const double fm = model.config().fps;
  const int W = model.config().window;
  RenavPlan plan;
  if (options.match_pace) plan.pace = reference_pace(reference, path, path_fps);
  Motion played = plan.pace == 1.0 ? reference : played_at_speed(reference, plan.pace);
  if (std::floor((played.num_frames() - 1) * fm / played.fps + 1e-6) < 1.0) {
    played = reference;  // too short to play faster: under two frames at the model's rate
    plan.pace = 1.0;
  }
  plan.reference = reference_at_model_rate(played, fm);
  plan.path = path_at_model_rate(path, path_fps, fm);
  const int overlap = options.overlap > 0 ? std::min(options.overlap, W / 2) : std::max(1, W / 4);
  plan.spans = renav_spans(static_cast<int>(plan.path.size()), plan.reference.num_frames(), W, overlap);
  plan.cap = options.max_iterations > 0 ? options.max_iterations : default_iterations(options.optimizer);
  return plan;
}

// Solves window `k` of `plan` given the solution so far (model rate) from the
// best of `inits`, and records its summary.
SolvedWindow solve_renav_window(const runtime::NemfRuntime& model, const RenavPlan& plan, int k, const Motion& so_far,
                                const RenavOptions& options, const std::vector<std::string>& inits, uint64_t seed,
                                const TaskContext& window_ctx, int iteration_offset, RenavReport* rep) {
  const auto t0 = Clock::now();
  const RenavSpan& span = plan.spans[k];
  const double fm = model.config().fps;
  const int total = plan.cap * static_cast<int>(plan.spans.size());
  window_ctx.report({iteration_offset, total, 0.0});
  const RenavWindow window = make_renav_window(model, plan.reference, span.ref_begin, span.ref_length, plan.path,
                                               span.start, span.length, k > 0 ? &so_far : nullptr, span.shared_end);
  RenavWindowSummary sum;
  sum.begin = span.start;
  sum.length = span.length;
  sum.reference_from = span.ref_begin * plan.pace / fm;
  sum.reference_to = (span.ref_begin + span.ref_length - 1) * plan.pace / fm;
  RenavWindowEnergies energy(model, window, options);
  const Eigen::VectorXd x0 = initial_codes(model, window, energy, inits, seed, k, &sum);
  const Eigen::VectorXd x =
      minimize_window(energy.energy(), x0, options.capped(plan.cap), window_ctx, iteration_offset, total, &sum);
  sum.runtime_energy = true;
  SolvedWindow solved{decode_solution(model, energy, x), window.transform, sum.iterations};
  sum.wall_ms = ms_since(t0);
  rep->windows.push_back(std::move(sum));
  return solved;
}

}  // namespace

Motion renavigate(const runtime::NemfRuntime& model, const Motion& reference, const std::vector<Eigen::Vector2d>& path,
                  double path_fps, const RenavOptions& options, const TaskContext& ctx, RenavReport* report) {
  const auto t0 = Clock::now();
  check_renav_input(model, reference, path, path_fps, options);
  const double fm = model.config().fps;
  const RenavPlan plan = plan_renav(model, reference, path, path_fps, options);
  const std::vector<std::string> inits = options.inits.empty() ? init_names() : options.inits;
  RenavReport rep;
  rep.pace = plan.pace;
  const int F = model.rig().num_feet();
  const WindowSolver solver(std::vector<WindowSpan>(plan.spans.begin(), plan.spans.end()), reference.skeleton,
                            static_cast<int>(plan.path.size()), fm, F);
  WindowedSolution out = solver.solve(ctx, [&](int k, const WindowedSolution& so_far, const TaskContext& window_ctx,
                                               int offset) {
    return solve_renav_window(model, plan, k, so_far.motion, options, inits, ctx.seed, window_ctx, offset, &rep);
  });

  if (options.foot_lock_ramp >= 0 && F > 0)
    lock_feet(model.rig(), MotionConstraints{}, out.contacts, options.foot_lock_ramp, &out.motion);
  const int N = static_cast<int>(path.size());
  Motion result = same_frame_rate(path_fps, fm) ? out.motion : resample_interpolate(out.motion, path_fps, N);
  result.fps = path_fps;
  measure_path_error(result, path, &rep);
  rep.iterations = out.iterations;
  rep.wall_ms = ms_since(t0);
  if (report) *report = std::move(rep);
  return result;
}

std::vector<std::string> renav_methods() { return {"nemf", "nemf-adam"}; }

namespace {

// A motion of `frames` frames at `fps` that holds `motion`'s first frame.
Motion hold_first_frame(const Motion& motion, int frames, double fps) {
  Motion out = Motion::identity(motion.skeleton, frames, fps);
  for (int f = 0; f < frames; ++f) {
    for (int j = 0; j < motion.num_joints(); ++j) out.rotation(f, j) = motion.rotation(0, j);
    out.root_positions[f] = motion.root_positions[0];
  }
  return out;
}

// Re-navigation of a reference on another rig than the model's: the
// reference is retargeted to the model's rig, the path scaled to the model's
// size (it is in the reference's metres), and the result brought back onto
// the reference's rig; joints the model lacks hold the reference's first pose.
Motion renavigate_on_model_rig(const Motion& reference, const std::vector<Eigen::Vector2d>& path, double fps,
                               const RenavOptions& options, const TaskContext& ctx, std::optional<RigMap> map,
                               RenavReport* report) {
  const Retargeter rig = model_retargeter(reference, {}, ctx, std::move(map));
  std::vector<Eigen::Vector2d> scaled = path;
  for (Eigen::Vector2d& p : scaled) p *= rig.scale();
  const Motion result = renavigate(*ctx.model, rig.to_model(reference), scaled, fps, options, ctx, report);
  if (report) {
    report->path_error_mean_cm /= rig.scale();
    report->path_error_max_cm /= rig.scale();
  }
  Motion back = rig.to_user(result, hold_first_frame(reference, result.num_frames(), fps));
  back.skeleton = reference.skeleton;
  back.fps = fps;
  return back;
}

}  // namespace

Motion run_renav(const Motion& reference, const std::vector<Eigen::Vector2d>& path, double path_fps,
                 const std::string& method, const TaskContext& ctx, RenavReport* report) {
  const std::string m = method.empty() ? renav_methods().front() : method;
  LatentOptimizer optimizer;
  if (m == "nemf") {
    optimizer = LatentOptimizer::Lbfgs;
  } else if (m == "nemf-adam") {
    optimizer = LatentOptimizer::Adam;
  } else {
    std::string list;
    for (const std::string& n : renav_methods()) list += (list.empty() ? "" : ", ") + n;
    throw InputError("unknown re-navigation method '" + method + "' (available: " + list + ")");
  }
  const runtime::NemfRuntime& model = require_prior(ctx, "re-navigation");
  std::optional<RigMap> rig_map = check_model_rig(reference.skeleton, ctx);
  if (reference.num_frames() < 2) throw InputError("the reference needs at least two frames");
  if (!(std::isfinite(reference.fps) && reference.fps > 0))
    throw InputError("the reference's fps must be finite and positive");
  if (!std::isfinite(path_fps) || path_fps < 0) throw InputError("the path's frame rate must be finite and positive");
  const double fps = path_fps > 0 ? path_fps : reference.fps;
  RenavOptions options = default_renav_options(optimizer);
  if (ctx.max_iterations > 0) options.max_iterations = ctx.max_iterations;
  // renavigate() takes any frame rate itself; only another rig needs the adapter.
  if (!reference.skeleton.same_as(model.rig().skeleton))
    return renavigate_on_model_rig(reference, path, fps, options, ctx, std::move(rig_map), report);
  return renavigate(model, reference, path, fps, options, ctx, report);
}

}  // namespace mf
