#include "capi/src/jobs/job.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <system_error>


namespace motionfield::jobs {
namespace {

using Clock = std::chrono::steady_clock;

constexpr char kStdio[] = "-";

// What a job checks before reading anything: its method exists, re-navigation's numbers.
void check_request(const BatchJob& job) {
  const bool renav = job.task == "renav";
  // Re-navigation has methods of its own, checked by mf_renav.
  if (!job.method.empty() && !renav) find_method(job.method);
  if (renav) {
    if (job.fps < 0 || !std::isfinite(job.fps)) throw InputError("renav: the fps must be positive");
    if (job.polyline && job.frames != 0 && job.frames < 2)
      throw InputError("renav: the frame count must be at least 2");
  }
  if (job.task == "transition" && job.to == kStdio)
    throw InputError("transition: clip B (\"to\") must be a file, not the standard input");
  if (job.out == kStdio && job.alternatives > 0)
    throw InputError("--alternatives writes OUT_1.bvh .. beside the output: name an output file, not -");
}

// The job's constraints: its file or inline JSON, plus the known frames of
// the task as whole-pose keys (a transition's: none, mf_transition adds them).
Constraints job_constraints(const BatchJob& job, const Motion& input) {
  Constraints c = !job.constraints_file.empty()   ? Constraints::load_json(job.constraints_file)
                  : !job.constraints_json.empty() ? Constraints::parse_json(job.constraints_json)
                                                  : Constraints::create();
  if (!job.trajectory_file.empty()) c.load_trajectory_csv(job.trajectory_file);
  if (job.task == "transition") return c;  // the library keys the clips' frames
  if (job.task == "inbetween" || job.has_keyframes)
    return std::move(c.add_pose_keys(std::vector<int32_t>(job.keyframes.begin(), job.keyframes.end())));
  const int n = input.frame_count();
  if (!(1 <= job.gap_begin && job.gap_begin < job.gap_end && job.gap_end <= n - 1))
    throw InputError("gap " + std::to_string(job.gap_begin) + ":" + std::to_string(job.gap_end) +
                     " must satisfy 1 <= A < B <= frames - 1 (the input has " + std::to_string(n) + " frames)");
  std::vector<int32_t> known;
  for (int f = 0; f < n; ++f)
    if (f < job.gap_begin || f >= job.gap_end) known.push_back(f);
  return std::move(c.add_pose_keys(known));
}

// What a job's solve gives: the motion and, with constraints, the
// alternatives and the report.
struct Solved {
  Motion motion;
  std::vector<Motion> alternatives;
  std::string report;
  std::string method;  ///< the method that ran, when the solve says (constrained jobs)
  int transition_frames = 0, transition_first = 0;  ///< a transition's N and its first frame
};

// The solution's motion, its alternatives and (with constraints) its report.
Solved solved_from(const BatchJob& job, const Solution& s) {
  Solved out{s.motion(0), {}, job.constrained() ? s.report_json() : std::string(), s.method()};
  for (int i = 1; i < s.count(); ++i) out.alternatives.push_back(s.motion(i));
  return out;
}

// A transition from the job's input (clip A) into clip B.
Solved solve_transition(const BatchJob& job, const Model& model, const Motion& a, const Motion& b,
                        const TaskOptions& options) {
  TransitionOptions t;
  t.frames = job.frames;
  t.from_frame = job.from_frame;
  t.to_frame = job.to_frame;
  t.place = job.place_keep ? MF_PLACE_KEEP : MF_PLACE_AUTO;
  t.only_transition = job.only_transition;
  const bool constrained = !job.constraints_file.empty() || !job.constraints_json.empty() || !job.trajectory_file.empty();
  const Solution s = transition(model, a, b, t, constrained ? job_constraints(job, a) : Constraints(),
                                job.alternatives, options);
  Solved out = solved_from(job, s);
  out.transition_frames = s.transition_frames();
  out.transition_first = s.transition_first_frame();
  return out;
}

// The plain tasks (whole-pose keys, a gap, resampling, re-navigation).
Motion solve_task(const BatchJob& job, const Model& model, const Motion& input, const TaskOptions& options) {
  if (job.task == "inbetween" || (job.task == "fill" && job.has_keyframes))
    return inbetween(model, input, std::vector<int32_t>(job.keyframes.begin(), job.keyframes.end()), options);
  if (job.task == "fill") return fill(model, input, job.gap_begin, job.gap_end, options);
  if (job.task == "resample") return resample(model, input, job.fps, options);
  if (job.task == "renav") {
    RenavOptions renav_options;
    renav_options.path_kind = job.polyline ? MF_PATH_POLYLINE : MF_PATH_PER_FRAME;
    renav_options.fps = job.fps;
    if (job.polyline) renav_options.frame_count = job.frames;
    return renav(model, input, load_path_csv(job.path_file), renav_options, options);
  }
  throw InputError("unknown task '" + job.task + "'");
}

Solved solve(const BatchJob& job, const JobSettings& settings, const Model& model, const Motion& input,
             const Motion& second, const ProgressFn& progress) {
  TaskOptions options(job.method);
  options.max_iterations = job.max_iterations;
  options.no_fallback = !job.fallback;
  options.rig_map_path = job.rig_map.empty() ? settings.rig_map : job.rig_map;
  options.progress = progress;
  if (job.task == "transition") return solve_transition(job, model, input, second, options);
  if (job.constrained())
    return solved_from(job, motionfield::solve(model, input, job_constraints(job, input), job.alternatives, options));
  return {solve_task(job, model, input, options), {}, "", ""};
}

// The method that ran.
std::string method_name(const BatchJob& job, const Model& model) {
  if (!job.method.empty() || job.task == "export") return job.method;
  if (job.task == "resample") return model ? "prior" : "quintic";
  if (job.task == "renav") return "nemf";
  return default_method(model);
}

// Writes the BVH text on standard output; InputError with the reason when it fails (a closed pipe, a full disk).
void write_stdout(const Motion& result) {
  const std::string text = result.to_bvh();
  errno = 0;
  const bool ok = std::fwrite(text.data(), 1, text.size(), stdout) == text.size() && std::fflush(stdout) == 0;
  if (!ok) throw Error(MF_ERROR_IO, std::string("cannot write the standard output: ") + std::strerror(errno));
}

// The glTF format an output's name asks for: MF_GLTF_BINARY for .glb,
// MF_GLTF_EMBEDDED for .gltf (any case), else -1 (BVH).
int gltf_format_of(const std::string& out) {
  const size_t dot = out.rfind('.');
  if (dot == std::string::npos || out.find('/', dot) != std::string::npos) return -1;
  std::string ext = out.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == "glb" ? MF_GLTF_BINARY : ext == "gltf" ? MF_GLTF_EMBEDDED : -1;
}

// Stages `result` for `out` in `files`: a .glb or .gltf name as glTF 2.0,
// anything else as BVH.
void stage_motion(OutputSet& files, const Motion& result, const std::string& out) {
  const int gltf = gltf_format_of(out);
  if (gltf >= 0)
    files.write(out, result.to_gltf(gltf));
  else
    files.write(out, result.to_bvh());
}

double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

// The line --verbose prints for a job that ran.
std::string verbose_line(const BatchJob& job, const JobReport& report, int threads) {
  char line[512];
  std::snprintf(line, sizeof line, ": %d -> %d frames, method %s, %d threads; read %.1f ms, solve %.1f ms, write %.1f ms",
                report.frames_in, report.frames_out, report.method.c_str(), threads, report.read_ms, report.solve_ms,
                report.write_ms);
  return job.task + " " + job.in + " -> " + job.out + ", model " +
         (report.model.empty() ? std::string("none") : report.model) + line;
}

// Stages every output of a solved job (the motion unless it goes to standard
// output, the alternatives, the report) and returns the alternatives' files.
std::vector<std::string> stage_outputs(const BatchJob& job, OutputSet& files, const Solved& solved,
                                       const Motion& result) {
  std::vector<std::string> alternatives;
  if (job.out != kStdio) stage_motion(files, result, job.out);
  for (size_t i = 0; i < solved.alternatives.size(); ++i) {
    alternatives.push_back(alternative_path(job.out, static_cast<int>(i) + 1));
    stage_motion(files, solved.alternatives[i], alternatives.back());
  }
  if (!job.report_file.empty()) files.write(job.report_file, solved.report + "\n");
  return alternatives;
}

}  // namespace

std::string alternative_path(const std::string& out, int index) {
  const std::filesystem::path p(out);
  return (p.parent_path() / (p.stem().string() + "_" + std::to_string(index) + p.extension().string())).string();
}

OutputSet prepare_job(const BatchJob& job, const JobSettings& settings) {
  check_request(job);
  OutputSet files = OutputSet::create();
  const std::string& rig_map = job.rig_map.empty() ? settings.rig_map : job.rig_map;
  if (job.in != kStdio) files.add_input(job.in, "input");
  files.add_input(job.to, "input");
  files.add_input(job.path_file, "path file");
  files.add_input(rig_map, "rig map file");
  files.add_input(job.constraints_file, "constraints file");
  files.add_input(job.trajectory_file, "trajectory file");
  if (job.out != kStdio) files.add_output(job.out, "output");
  for (int i = 1; i <= job.alternatives; ++i) files.add_output(alternative_path(job.out, i), "alternative");
  if (!job.report_file.empty()) files.add_output(job.report_file, "report");
  return files;
}

JobReport run_job(const BatchJob& job, OutputSet files, const JobSettings& settings, Models& models,
                  const ProgressFn& progress, bool load_warnings) {
  const auto t0 = Clock::now();
  // Export writes the input as it is read: no method, no model.
  const bool export_only = job.task == "export";
  static const Model kNoModel;
  // Re-navigation always needs the prior, whatever the method.
  const Model& model =
      export_only ? kNoModel : models.for_method(job.task == "renav" && job.method.empty() ? "nemf" : job.method);
  JobReport report;
  // What the default method lost.
  if (load_warnings && job.method.empty() && !export_only) report.warnings = Models::load_warnings_of(model);
  // Standard input through its device file: the library reads pipes and
  // redirected files with its size limit, and refuses a terminal.
  LoadOptions load;
  load.length_scale = units_scale(job.units.empty() ? settings.units : job.units,
                                  job.units.empty() ? "--units (--length-scale)" : "\"units\"");
  load.animation = job.animation;
  load.animation_index = job.animation_index;
  const Motion input = Motion::load(job.in == kStdio ? "/dev/stdin" : job.in, load);
  const Motion second = job.to.empty() ? Motion() : Motion::load(job.to, load);
  const auto t1 = Clock::now();
  const Solved solved = export_only ? Solved{} : solve(job, settings, model, input, second, progress);
  const Motion& result = export_only ? input : solved.motion;
  const auto t2 = Clock::now();
  // Every output staged, standard output written, then all put in place at
  // once: a failure leaves none of them behind.
  report.alternatives = stage_outputs(job, files, solved, result);
  if (job.out == kStdio) write_stdout(result);
  files.commit();
  report.constraints = solved.report;
  const auto t3 = Clock::now();

  report.method = solved.method.empty() ? method_name(job, model) : solved.method;
  report.model = model ? models.path() : "";
  report.frames_in = input.frame_count();
  report.frames_out = result.frame_count();
  report.read_ms = ms(t1 - t0);
  report.solve_ms = ms(t2 - t1);
  report.write_ms = ms(t3 - t2);
  report.transition_frames = solved.transition_frames;
  report.transition_first = solved.transition_first;
  report.warnings += result.warnings();
  if (settings.verbose) report.verbose = verbose_line(job, report, settings.threads);
  return report;
}

std::string job_json(const BatchJob& job, const JobReport* report, const Failure* failure, size_t line) {
  nlohmann::ordered_json j;
  if (line > 0) j["line"] = line;
  if (!job.id.empty()) j["id"] = job.id;
  j["task"] = job.task;
  j["in"] = job.in;
  j["out"] = job.out;
  if (failure) {
    j["status"] = "error";
    j["exit_code"] = failure->exit_code;
    j["error"] = failure->message;
  } else if (report) {
    j["status"] = "ok";
    j["method"] = report->method;
    j["model"] = report->model;
    j["frames_in"] = report->frames_in;
    j["frames_out"] = report->frames_out;
    j["timings_ms"] = {{"read", report->read_ms},
                       {"solve", report->solve_ms},
                       {"write", report->write_ms},
                       {"total", report->read_ms + report->solve_ms + report->write_ms}};
    nlohmann::ordered_json warnings = nlohmann::ordered_json::array();
    std::istringstream lines(report->warnings);
    for (std::string w; std::getline(lines, w);) warnings.push_back(w);
    j["warnings"] = warnings;
    if (report->transition_frames > 0)
      j["transition"] = {{"frames", report->transition_frames}, {"first_frame", report->transition_first}};
    if (!report->constraints.empty()) {
      j["alternatives"] = report->alternatives;
      j["constraints"] = nlohmann::ordered_json::parse(report->constraints);
    }
  }
  // Invalid UTF-8 in a file name becomes U+FFFD rather than failing the summary.
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace motionfield::jobs
