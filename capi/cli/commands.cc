#include "commands.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

#include "input_error.h"
#include "job.h"
#include "models.h"
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

// The job of a task command (inbetween, fill, resample, renav) from its options.
BatchJob task_job(const std::string& command, const Arguments& a) {
  BatchJob job = a.job;
  job.task = command;
  if (command == "inbetween") {
    job.keyframes = parse_int_list(a.keyframes, "--keyframes");
    job.has_keyframes = true;
  } else if (command == "fill") {
    const size_t colon = a.gap.find(':');
    if (colon == std::string::npos) throw InputError("bad value for --gap: '" + a.gap + "' (expected A:B, e.g. 10:20)");
    job.gap_begin = parse_int(trim(a.gap.substr(0, colon)), "--gap");
    job.gap_end = parse_int(trim(a.gap.substr(colon + 1)), "--gap");
    job.has_gap = true;
  } else if (command == "renav") {
    if (a.path.empty() == a.polyline.empty())
      throw InputError("renav: give exactly one of --path and --polyline (see motionfield renav --help)");
    job.polyline = !a.polyline.empty();
    job.path_file = job.polyline ? a.polyline : a.path;
  }
  return job;
}

int command_task(const BatchJob& job, const Settings& settings) {
  if (settings.json && job.out == "-")
    throw InputError("--json and --out - would both write to standard output: name an output file");
  Models models(settings.model, settings.transformers());
  models.load_explicit();
  ProgressLine progress(ProgressLine::stderr_is_terminal() && !settings.quiet);
  progress.start(job.task + " " + job.in);
  JobReport report;
  try {
    report = run_job(job, settings, models, progress);
  } catch (...) {
    progress.clear();
    if (settings.json) {
      Failure failure = current_failure();
      failure.message = printable(failure.message);
      std::printf("%s\n", job_json(job, nullptr, &failure).c_str());
    }
    throw;
  }
  if (!settings.quiet) print_warnings(report.warnings);
  if (settings.json) std::printf("%s\n", job_json(job, &report, nullptr).c_str());
  return kExitOk;
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
    Model model = Model::load(path);
    for (const std::string& file : settings.transformers()) model = model.with_inbetweener(file);
    const JsonValue d = parse_json(model.describe());
    std::string transformers;
    const JsonValue& kinds = *d.find("inbetweeners");
    for (size_t i = 0; i < kinds.keys().size(); ++i)
      if (kinds.values()[i].find("loaded")->as_bool()) transformers += (transformers.empty() ? "" : ", ") + kinds.keys()[i];
    std::printf("%s\n", printable("model " + path + ": format " +
                                   std::to_string(static_cast<int>(d.find("format_version")->as_number())) + ", " +
                                   std::to_string(static_cast<int>(d.find("joints")->as_number())) + " joints at " +
                                   std::to_string(static_cast<int>(d.find("fps")->as_number())) + " fps, window " +
                                   std::to_string(static_cast<int>(d.find("window")->as_number())) +
                                   "; transformers: " + (transformers.empty() ? "none" : transformers))
                             .c_str());
    if (!settings.quiet) print_warnings(Models::load_warnings_of(model));
  } catch (const Error& e) {
    std::printf("%s\n", printable("model " + path + ": does not load: " + e.what()).c_str());
  }
  return kExitOk;
}

// The text form of mf_rig_describe's JSON (names from the file printable).
void print_rig(const std::string& in, const JsonValue& d, const std::string& model_path, bool units_given) {
  const bool detected = d.find("unit_detected")->as_bool();
  const char* unit_how = units_given ? "given" : detected ? "detected from the leg length" : "no legs found: assumed";
  std::printf("%s: %d joints, unit %s (%s; %g m per file unit)\n", printable(in).c_str(),
              static_cast<int>(d.find("joints")->as_number()), d.find("unit")->as_string().c_str(), unit_how,
              d.find("length_scale")->as_number());
  std::printf("mapped onto %s (%zu joints): user joint -> model joint, found by\n", printable(model_path).c_str(),
              d.find("model_joints")->as_array().size());
  const JsonValue& map = *d.find("map");
  const JsonValue& how = *d.find("how");
  size_t width = 0;
  for (const std::string& user : map.keys()) width = std::max(width, printable(user).size());
  for (size_t i = 0; i < map.keys().size(); ++i) {
    const std::string& model_joint = map.values()[i].as_string();
    std::printf("  %-*s -> %-14s %s\n", static_cast<int>(width), printable(map.keys()[i]).c_str(), model_joint.c_str(),
                how.find(model_joint)->as_string().c_str());
  }
  std::string left;
  for (const JsonValue& j : d.find("unmapped_user_joints")->as_array())
    left += (left.empty() ? "" : ", ") + j.as_string();
  std::printf("user joints left out: %s\n", left.empty() ? "none" : printable(left).c_str());
  const std::string anatomy = d.find("anatomy")->as_string();
  if (anatomy == "rest pose")
    std::printf("joint frames: read from the rest pose (a T or A pose)\n");
  else if (anatomy == "known frames")
    std::printf("joint frames: measured on each input's known frames (the rest pose is not a T or A pose)\n");
  if (!d.find("retargeting")->as_bool())
    std::printf(
        "note: the model has no rig anatomy (motionfield-rig.json next to it): "
        "only its own rig can be solved\n");
}

int command_rig(const std::string& in, bool json, const Settings& settings) {
  // The library's reader of rig maps, with their limit (1 MiB), as the tasks read them.
  const std::string map = settings.rig_map.empty() ? "" : rig_map_read_file(settings.rig_map);
  Models models(settings.model, settings.transformers());
  const Model& model = models.required("rig");
  const double length_scale = units_scale(settings.units, "--units (--length-scale)");
  const Motion motion = Motion::load_bvh(in, length_scale);
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
    print_rig(in, parse_json(text), models.path(), length_scale > 0);
  }
  return kExitOk;
}

}  // namespace

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
  return command_task(task_job(command, args), settings);
}

}  // namespace motionfield::cli
