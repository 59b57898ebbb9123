#include "commands.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "motionfield.hpp"
#include "progress.h"

namespace motionfield::cli {
namespace {

int parse_int(const std::string& text, const std::string& what) {
  int v = 0;
  const char* b = text.data();
  const char* e = b + text.size();
  const auto r = std::from_chars(b, e, v);
  if (text.empty() || r.ec != std::errc() || r.ptr != e)
    throw InputError("bad integer for " + what + ": '" + text + "'");
  return v;
}

std::string trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t')) --e;
  return s.substr(b, e - b);
}

// "0, 10,20": every item an integer (no empty items).
std::vector<int> parse_int_list(const std::string& text, const std::string& what) {
  std::vector<int> out;
  std::istringstream items(text + ",");
  for (std::string item; std::getline(items, item, ',');) out.push_back(parse_int(trim(item), what));
  return out;
}

// A number as a job line holds it; a non-finite one as its text (JSON has
// none), for the library's own check.
nlohmann::ordered_json number(double v) {
  if (std::isfinite(v)) return v;
  return std::isnan(v) ? "nan" : v > 0 ? "inf" : "-inf";
}

// The job line of a task command (inbetween, fill, resample, renav, transition, export)
// from its options: the library runs it as a batch line.
// --animation as a job line has it: an index (digits only) or a name.
nlohmann::ordered_json animation_value(const std::string& text) {
  if (!text.empty() && text.find_first_not_of("0123456789") == std::string::npos) return parse_int(text, "--animation");
  return text;
}

std::string task_line(const std::string& command, const Arguments& a) {
  const JobOptions& job = a.job;
  nlohmann::ordered_json j{{"task", command}, {"in", job.in}, {"out", job.out}};
  if (!job.method.empty()) j["method"] = job.method;
  if (job.max_iterations != 0) j["max_iterations"] = job.max_iterations;
  if (command == "inbetween") j["keyframes"] = parse_int_list(a.keyframes, "--keyframes");
  if (command == "fill") {
    const size_t colon = a.gap.find(':');
    if (colon == std::string::npos) throw InputError("bad value for --gap: '" + a.gap + "' (expected A:B, e.g. 10:20)");
    j["gap"] = {parse_int(trim(a.gap.substr(0, colon)), "--gap"), parse_int(trim(a.gap.substr(colon + 1)), "--gap")};
  }
  if (command == "resample") j["fps"] = number(job.fps);
  if (command == "renav") {
    if (a.path.empty() == a.polyline.empty())
      throw InputError("renav: give exactly one of --path and --polyline (see motionfield renav --help)");
    j[a.polyline.empty() ? "path" : "polyline"] = a.polyline.empty() ? a.path : a.polyline;
    if (job.fps != 0) j["fps"] = number(job.fps);
    if (job.frames != 0) j["frames"] = job.frames;
  }
  if (command == "transition") {
    j["to"] = a.to;
    if (job.frames != 0) j["frames"] = job.frames;
    j["from_frame"] = a.from_frame;
    j["to_frame"] = a.to_frame;
    j["place"] = a.place;
    if (a.only_transition) j["only_transition"] = true;
  }
  if (!job.constraints_file.empty()) j["constraints"] = job.constraints_file;
  if (!job.trajectory_file.empty()) j["trajectory"] = job.trajectory_file;
  if (job.alternatives != 0) j["alternatives"] = job.alternatives;
  if (!job.report_file.empty()) j["report"] = job.report_file;
  if (job.no_fallback) j["fallback"] = false;
  if (!a.settings.animation.empty()) j["animation"] = animation_value(a.settings.animation);
  try {
    return j.dump();
  } catch (const nlohmann::json::exception&) {
    throw InputError("file names must be UTF-8 text: " + printable(job.in + (a.to.empty() ? "" : " " + a.to) + " -> " + job.out));
  }
}

int command_task(const std::string& command, const Arguments& args) {
  const Settings& settings = args.settings;
  if (settings.json && args.job.out == "-")
    throw InputError("--json and --out - would both write to standard output: name an output file");
  const std::string line = task_line(command, args);
  JobRunner runner = make_runner(settings);
  ProgressLine progress(ProgressLine::stderr_is_terminal() && !settings.quiet);
  progress.start(command + " " + args.job.in);
  std::function<bool(const mf_progress&)> report;
  if (progress.enabled()) report = [&progress](const mf_progress& p) { return progress.update(p); };
  const JobResult result = runner.run_line(line, 0, "", MF_JOB_SINGLE | MF_JOB_LOAD_WARNINGS, report);
  progress.clear();
  std::fputs(result.messages.c_str(), stderr);
  if (settings.json) std::printf("%s\n", result.json.c_str());
  return result.exit_code;
}

// motionfield --version: the program's, the library's and the ABI's versions,
// and the model's when one is found (--model or the default one).
int command_version(const Settings& settings) {
  std::printf("motionfield %s\n", MF_VERSION_STRING);
  std::printf("library %s, ABI %u (this program was built against %s, ABI %d)\n", version().c_str(),
              static_cast<unsigned>(abi_version()), MF_VERSION_STRING, MF_ABI_VERSION);
  const std::string path = settings.model.empty() ? default_model_path() : settings.model;
  if (path.empty()) {
    std::printf("model: none found (--model PATH, $MF_MODEL or models/motionfield-prior.mfm)\n");
    return kExitOk;
  }
  try {
    const Model model = Model::load_set(path, settings.transformers());
    const nlohmann::ordered_json d = nlohmann::ordered_json::parse(model.describe());
    std::string transformers;
    for (const auto& [kind, about] : d["inbetweeners"].items())
      if (about["loaded"].get<bool>()) transformers += (transformers.empty() ? "" : ", ") + kind;
    std::printf("%s\n", printable("model " + path + ": format " + std::to_string(d["format_version"].get<int>()) +
                                   ", " + std::to_string(d["joints"].get<int>()) + " joints at " +
                                   std::to_string(static_cast<int>(d["fps"].get<double>())) + " fps, window " +
                                   std::to_string(d["window"].get<int>()) +
                                   "; transformers: " + (transformers.empty() ? "none" : transformers))
                             .c_str());
    if (!settings.quiet) print_warnings(model.load_warnings());
  } catch (const Error& e) {
    std::printf("%s\n", printable("model " + path + ": does not load: " + e.what()).c_str());
  }
  return kExitOk;
}

// The text form of mf_rig_describe's JSON (names from the file printable).
void print_rig(const std::string& in, const nlohmann::ordered_json& d, const std::string& model_path, bool units_given) {
  const bool detected = d["unit_detected"].get<bool>();
  const bool from_file = d["unit_from_file"].get<bool>();
  const char* unit_how = from_file     ? "from the file"
                         : units_given ? "given"
                         : detected    ? "detected from the leg length"
                                       : "no legs found: assumed";
  std::printf("%s: %d joints, unit %s (%s; %g m per file unit)\n", printable(in).c_str(), d["joints"].get<int>(),
              d["unit"].get<std::string>().c_str(), unit_how, d["length_scale"].get<double>());
  std::printf("mapped onto %s (%zu joints): user joint -> model joint, found by\n", printable(model_path).c_str(),
              d["model_joints"].size());
  const nlohmann::ordered_json& map = d["map"];
  const nlohmann::ordered_json& how = d["how"];
  size_t width = 0;
  for (const auto& [user, model_joint] : map.items()) width = std::max(width, printable(user).size());
  for (const auto& [user, model_joint] : map.items()) {
    const std::string joint = model_joint.get<std::string>();
    std::printf("  %-*s -> %-14s %s\n", static_cast<int>(width), printable(user).c_str(), joint.c_str(),
                how[joint].get<std::string>().c_str());
  }
  std::string left;
  for (const auto& j : d["unmapped_user_joints"]) left += (left.empty() ? "" : ", ") + j.get<std::string>();
  std::printf("user joints left out: %s\n", left.empty() ? "none" : printable(left).c_str());
  const std::string anatomy = d["anatomy"].get<std::string>();
  if (anatomy == "rest pose")
    std::printf("joint frames: read from the rest pose (a T or A pose)\n");
  else if (anatomy == "known frames")
    std::printf("joint frames: measured on each input's known frames (the rest pose is not a T or A pose)\n");
  if (!d["retargeting"].get<bool>())
    std::printf(
        "note: the model has no rig anatomy (motionfield-rig.json next to it): "
        "only its own rig can be solved\n");
}

int command_rig(const std::string& in, bool json, const Settings& settings) {
  // The library's reader of rig maps, with their limit (1 MiB), as the tasks read them.
  const std::string map = settings.rig_map.empty() ? "" : rig_map_read_file(settings.rig_map);
  JobRunner runner = make_runner(settings);
  const Model model = runner.load_model();
  if (!model) throw InputError("rig needs the model, and none is installed (name one with --model)");
  const double length_scale = units_scale(settings.units, "--units (--length-scale)");
  LoadOptions load;
  load.length_scale = length_scale;
  const nlohmann::ordered_json animation = animation_value(settings.animation);
  if (animation.is_string()) load.animation = animation.get<std::string>();
  else load.animation_index = animation.get<int>();
  const Motion motion = Motion::load(in, load);
  std::string text;
  try {
    text = rig_describe(model, motion, map);
  } catch (const Error& e) {
    if (e.status() == MF_ERROR_INVALID_ARGUMENT && !settings.rig_map.empty())
      throw InputError(settings.rig_map + ": " + e.what());
    throw;
  }
  if (json) {
    std::printf("%s\n", text.c_str());  // JSON: control characters are escaped
  } else {
    print_rig(in, nlohmann::ordered_json::parse(text), runner.model_path(), length_scale > 0);
  }
  return kExitOk;
}

}  // namespace

JobRunner make_runner(const Settings& settings, uint32_t flags) {
  JobRunnerOptions options;
  options.flags = flags | (settings.verbose ? MF_JOB_VERBOSE : 0u) | (settings.quiet ? MF_JOB_QUIET : 0u);
  options.threads = settings.threads;
  options.model = settings.model;
  options.inbetweeners = settings.transformers();
  options.rig_map = settings.rig_map;
  options.units = settings.units;
  return JobRunner::create(options);
}

int run_command(const CLI::App& app, const Arguments& args) {
  const Settings& settings = args.settings;
  if (args.version) return command_version(settings);
  units_scale(settings.units, "--units (--length-scale)");
  const std::vector<CLI::App*> chosen = app.get_subcommands();
  if (chosen.empty()) {
    std::fputs(app.help().c_str(), stderr);
    throw InputError("no command given");
  }
  const std::string command = chosen.front()->get_name();
  set_num_threads(settings.threads);
  if (settings.verbose) std::fprintf(stderr, "motionfield: %d intra-op threads\n", settings.threads);

  if (command == "batch") return command_batch(args.file, settings);
  if (command == "rig") return command_rig(args.file, settings.json, settings);
  return command_task(command, args);
}

}  // namespace motionfield::cli
