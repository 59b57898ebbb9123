// motionfield: the command-line front end (in-betweening, gap filling,
// resampling, batch runs). Exit codes: 0 ok, 2 bad input, 1 internal error;
// every message goes to stderr, prefixed with "motionfield: ".
#include <ATen/Parallel.h>
#include <unistd.h>

#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "capi/cli/jsonl.h"
#include "prior/motion/bvh.h"
#include "prior/motion/errors.h"
#include "prior/motion/motion_bvh.h"
#include "prior/motion/rotations.h"
#include "tasks/jobs.h"

#ifndef MF_VERSION
#define MF_VERSION "unknown"
#endif

namespace {

constexpr int kExitOk = 0;
constexpr int kExitInternal = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitDiffer = 3;  // only `motionfield diff`

using mf::InputError;

// ---------------------------------------------------------------- help texts

const char* kMainHelp =
    "motionfield " MF_VERSION ": motion in-betweening, gap filling and resampling of BVH clips\n"
    "\n"
    "usage: motionfield [--threads N] [--verbose] <command> [options]\n"
    "\n"
    "commands:\n"
    "  inbetween  fill the frames between sparse keyframes\n"
    "  fill       fill a gap of unknown frames\n"
    "  resample   change the frame rate, keeping the time span\n"
    "  batch      run many jobs from a JSON Lines file in one process\n"
    "\n"
    "global options:\n"
    "  --threads N    intra-op threads for the solvers (default 2)\n"
    "  --verbose, -v  print what runs and how long it takes (stderr)\n"
    "  --help, -h     this help; `motionfield <command> --help` for a command\n"
    "  --version      print the version\n"
    "\n"
    "Output BVH files keep the input's skeleton, channel layout and frame time.\n"
    "Exit codes: 0 ok, 2 bad input (message on stderr), 1 internal error.\n";

const char* kInbetweenHelp =
    "usage: motionfield inbetween --in IN.bvh --keyframes K0,K1,... --out OUT.bvh [--method M]\n"
    "\n"
    "Keeps the keyframes (0-based frame indices, strictly increasing, at least two)\n"
    "and fills every other frame. Frames before the first and after the last\n"
    "keyframe hold that keyframe. The output has the input's length.\n"
    "\n"
    "  --in PATH         input BVH\n"
    "  --keyframes LIST  comma-separated frame indices, e.g. 0,10,20,29\n"
    "  --out PATH        output BVH (written atomically)\n"
    "  --method M        interp (default: LERP root, SLERP rotations) or zerovel\n";

const char* kFillHelp =
    "usage: motionfield fill --in IN.bvh --gap A:B --out OUT.bvh [--method M]\n"
    "\n"
    "Frames A..B-1 are unknown and filled; every other frame is kept. The gap must\n"
    "leave at least one known frame on each side: 1 <= A < B <= frames - 1.\n"
    "\n"
    "  --in PATH   input BVH\n"
    "  --gap A:B   the unknown frames, A inclusive, B exclusive\n"
    "  --out PATH  output BVH (written atomically)\n"
    "  --method M  interp (default) or zerovel\n";

const char* kResampleHelp =
    "usage: motionfield resample --in IN.bvh --fps F --out OUT.bvh [--method M]\n"
    "\n"
    "Resamples to F frames per second keeping the time span: N frames at f_in give\n"
    "(N-1)*F/f_in + 1 frames at F. A non-integer count is rounded down (with a\n"
    "warning on stderr). The output's frame time is 1/F.\n"
    "\n"
    "  --in PATH   input BVH\n"
    "  --fps F     target frame rate, e.g. 60\n"
    "  --out PATH  output BVH (written atomically)\n"
    "  --method M  interp (default) or zerovel\n";

const char* kBatchHelp =
    "usage: motionfield batch JOBS.jsonl\n"
    "\n"
    "Runs one job per line of JOBS.jsonl, each a JSON object:\n"
    "  {\"task\": \"inbetween\", \"in\": \"a.bvh\", \"out\": \"b.bvh\", \"keyframes\": [0, 10, 20]}\n"
    "  {\"task\": \"fill\", \"in\": \"a.bvh\", \"out\": \"c.bvh\", \"gap\": [10, 20]}\n"
    "  {\"task\": \"resample\", \"in\": \"a.bvh\", \"out\": \"d.bvh\", \"fps\": 60, \"method\": \"interp\"}\n"
    "For fill, a \"keyframes\" list, if given, is authoritative over \"gap\". Keys a\n"
    "job does not need (\"id\", frame counts, ...) are ignored; blank lines are\n"
    "skipped; relative paths are relative to the current directory.\n"
    "A failed job is reported on stderr (line number, id, reason) and the others\n"
    "still run. Exit code: 0 if every job succeeded, 1 if any job hit an internal\n"
    "error, otherwise 2 if any job had bad input. Progress is shown on stderr when\n"
    "it is a terminal.\n";

const char* kDiffHelp =
    "usage: motionfield diff A.bvh B.bvh [--tol T] [--frames LIST] [--step K]\n"
    "\n"
    "(A testing aid.) Compares frame f of A with frame f*K of B (K = --step,\n"
    "default 1) for every f in LIST (default: every frame of A): root position\n"
    "in file units and local rotations in degrees, both within T (default 1e-4),\n"
    "and the joint names. Without --frames and --step, the frame counts and frame\n"
    "times must also agree. Prints the largest differences. Exit 0 if equal,\n"
    "3 if they differ, 2 on bad input.\n";

// ---------------------------------------------------------------- parsing

int parse_int(const std::string& text, const std::string& what) {
  int v = 0;
  const char* b = text.data();
  const char* e = b + text.size();
  const auto r = std::from_chars(b, e, v);
  if (text.empty() || r.ec != std::errc() || r.ptr != e)
    throw InputError("bad integer for " + what + ": '" + text + "'");
  return v;
}

double parse_double(const std::string& text, const std::string& what) {
  double v = 0;
  const char* b = text.data();
  const char* e = b + text.size();
  const auto r = std::from_chars(b, e, v);
  if (text.empty() || r.ec != std::errc() || r.ptr != e || !std::isfinite(v))
    throw InputError("bad number for " + what + ": '" + text + "'");
  return v;
}

std::string trim(const std::string& s) {
  size_t b = 0, e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t')) --e;
  return s.substr(b, e - b);
}

std::vector<int> parse_int_list(const std::string& text, const std::string& what) {
  std::vector<int> out;
  size_t start = 0;
  while (true) {
    const size_t comma = text.find(',', start);
    out.push_back(parse_int(trim(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start)), what));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return out;
}

struct Gap {
  int a = 0, b = 0;
};

Gap parse_gap(const std::string& text) {
  const size_t colon = text.find(':');
  if (colon == std::string::npos) throw InputError("bad value for --gap: '" + text + "' (expected A:B, e.g. 10:20)");
  return {parse_int(trim(text.substr(0, colon)), "--gap"), parse_int(trim(text.substr(colon + 1)), "--gap")};
}

// Options of one command: --name VALUE or --name=VALUE, each at most once,
// plus positional arguments.
struct CommandArgs {
  std::map<std::string, std::string> flags;
  std::vector<std::string> positional;
  bool help = false;

  bool has(const std::string& name) const { return flags.count(name) != 0; }
  const std::string& get(const std::string& name) const { return flags.at(name); }
  std::string required(const std::string& name, const std::string& command) const {
    if (!has(name)) throw InputError(command + ": missing --" + name + " (see motionfield " + command + " --help)");
    return get(name);
  }
};

CommandArgs parse_command_args(const std::string& command, const std::vector<std::string>& args,
                               const std::set<std::string>& allowed) {
  CommandArgs out;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      out.help = true;
      continue;
    }
    if (a.size() > 2 && a.compare(0, 2, "--") == 0) {
      std::string name = a.substr(2), value;
      const size_t eq = name.find('=');
      const bool inline_value = eq != std::string::npos;
      if (inline_value) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
      }
      if (!allowed.count(name))
        throw InputError(command + ": unknown option --" + name + " (see motionfield " + command + " --help)");
      if (!inline_value) {
        if (i + 1 >= args.size()) throw InputError(command + ": --" + name + " needs a value");
        value = args[++i];
      }
      if (out.flags.count(name)) throw InputError(command + ": --" + name + " is given more than once");
      out.flags[name] = value;
    } else if (a.size() > 1 && a[0] == '-' && !(a[1] >= '0' && a[1] <= '9')) {
      throw InputError(command + ": unknown option " + a + " (see motionfield " + command + " --help)");
    } else {
      out.positional.push_back(a);
    }
  }
  return out;
}

// ---------------------------------------------------------------- running jobs

struct Settings {
  int threads = 2;
  bool verbose = false;
};

bool is_known_method(const std::string& m) {
  for (const std::string& a : mf::available_methods())
    if (a == m) return true;
  return false;
}

void check_method(const std::string& m) {
  if (m.empty() || is_known_method(m)) return;
  std::string list;
  for (const std::string& a : mf::available_methods()) list += (list.empty() ? "" : ", ") + a;
  throw InputError("unknown method '" + m + "' (available: " + list + ")");
}

void check_output_path(const std::string& out) {
  namespace fs = std::filesystem;
  const fs::path p(out);
  std::error_code ec;
  if (fs::is_directory(p, ec)) throw InputError("cannot write " + out + ": it is a directory");
  const fs::path dir = p.parent_path();
  if (!dir.empty() && !fs::is_directory(dir, ec))
    throw InputError("cannot write " + out + ": directory " + dir.string() + " does not exist");
}

// Runs one job (from the command line or a batch line) end to end: read, solve,
// write. Warnings are appended to *warnings.
void run_job(const mf::cli::BatchJob& job, const Settings& settings, std::vector<std::string>* warnings) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  check_method(job.method);
  check_output_path(job.out);

  mf::BvhDocument layout;
  const mf::Motion input = mf::read_motion(job.in, &layout);
  const auto t1 = Clock::now();

  mf::Motion result;
  int expected_frames = input.num_frames();
  if (job.task == "inbetween" || (job.task == "fill" && job.has_keyframes)) {
    result = mf::run_inbetween(input, job.keyframes, job.method);
  } else if (job.task == "fill") {
    result = mf::run_fill(input, job.gap_begin, job.gap_end, job.method);
  } else if (job.task == "resample") {
    result = mf::run_resample(input, job.fps, job.method, warnings);
    expected_frames = mf::resampled_frame_count(input.num_frames(), input.fps, job.fps, nullptr);
  } else {
    throw InputError("unknown task '" + job.task + "'");
  }
  const auto t2 = Clock::now();

  mf::BvhDocument doc = mf::motion_to_bvh(result, layout);
  // Same-rate tasks keep the input's frame time as written (0.0333333 stays
  // 0.0333333, not 1 / (1 / 0.0333333)).
  if (job.task != "resample") doc.frame_time = layout.frame_time;
  if (doc.num_frames != expected_frames)
    throw std::logic_error("the result has " + std::to_string(doc.num_frames) + " frames, expected " +
                           std::to_string(expected_frames));
  try {
    mf::write_bvh_file(job.out, doc);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError("cannot write " + job.out + ": " + e.what());
  }
  const auto t3 = Clock::now();

  if (settings.verbose) {
    auto ms = [](Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
    std::fprintf(stderr,
                 "motionfield: %s %s -> %s: %d -> %d frames, method %s, %d threads; read %.1f ms, solve %.1f ms, "
                 "write %.1f ms\n",
                 job.task.c_str(), job.in.c_str(), job.out.c_str(), input.num_frames(), doc.num_frames,
                 (job.method.empty() ? mf::default_method() : job.method).c_str(), settings.threads, ms(t1 - t0),
                 ms(t2 - t1), ms(t3 - t2));
  }
}

void print_warnings(const std::vector<std::string>& warnings, const std::string& prefix) {
  for (const std::string& w : warnings) std::fprintf(stderr, "motionfield: %swarning: %s\n", prefix.c_str(), w.c_str());
}

int command_single(const std::string& command, const std::vector<std::string>& args, const Settings& settings) {
  const std::string task_flag = command == "inbetween" ? "keyframes" : command == "fill" ? "gap" : "fps";
  const CommandArgs a = parse_command_args(command, args, {"in", "out", "method", task_flag});
  if (a.help) {
    std::fputs(command == "inbetween" ? kInbetweenHelp : command == "fill" ? kFillHelp : kResampleHelp, stdout);
    return kExitOk;
  }
  if (!a.positional.empty())
    throw InputError(command + ": unexpected argument '" + a.positional.front() + "' (see motionfield " + command +
                     " --help)");
  mf::cli::BatchJob job;
  job.task = command;
  job.in = a.required("in", command);
  job.out = a.required("out", command);
  const std::string task_value = a.required(task_flag, command);
  if (a.has("method")) {
    job.method = a.get("method");
    if (job.method.empty()) throw InputError(command + ": --method needs a value");
  }
  if (command == "inbetween") {
    job.keyframes = parse_int_list(task_value, "--keyframes");
    job.has_keyframes = true;
  } else if (command == "fill") {
    const Gap g = parse_gap(task_value);
    job.gap_begin = g.a;
    job.gap_end = g.b;
    job.has_gap = true;
  } else {
    job.fps = parse_double(task_value, "--fps");
  }
  std::vector<std::string> warnings;
  run_job(job, settings, &warnings);
  print_warnings(warnings, "");
  return kExitOk;
}

bool blank(const std::string& line) {
  for (char c : line)
    if (c != ' ' && c != '\t' && c != '\r' && c != '\n') return false;
  return true;
}

int command_batch(const std::vector<std::string>& args, const Settings& settings) {
  const CommandArgs a = parse_command_args("batch", args, {});
  if (a.help) {
    std::fputs(kBatchHelp, stdout);
    return kExitOk;
  }
  if (a.positional.size() != 1)
    throw InputError("batch: expected exactly one JOBS.jsonl argument (see motionfield batch --help)");
  const std::string& path = a.positional.front();
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("cannot open " + path);
  std::vector<std::string> lines;
  for (std::string line; std::getline(file, line);) lines.push_back(line);
  if (file.bad()) throw InputError("cannot read " + path);
  if (!lines.empty() && lines[0].compare(0, 3, "\xEF\xBB\xBF") == 0) lines[0].erase(0, 3);  // UTF-8 BOM

  int total = 0;
  for (const std::string& l : lines) total += blank(l) ? 0 : 1;
  const bool progress = isatty(STDERR_FILENO) == 1;
  int done = 0, bad = 0, internal = 0;
  auto clear_progress = [&] {
    if (progress) std::fputs("\r\033[K", stderr);
  };
  for (size_t i = 0; i < lines.size(); ++i) {
    if (blank(lines[i])) continue;
    std::string label = path + " line " + std::to_string(i + 1);
    std::vector<std::string> warnings;
    if (progress) {
      std::fprintf(stderr, "\r\033[K[%d/%d] line %zu", done + 1, total, i + 1);
      std::fflush(stderr);
    }
    try {
      mf::cli::JsonValue value;
      try {
        value = mf::cli::parse_json(lines[i]);
      } catch (const mf::cli::JsonError& e) {
        throw InputError(std::string("invalid JSON: ") + e.what());
      }
      if (const mf::cli::JsonValue* id = value.find("id"))
        label += " (id " + (id->is_string() ? id->as_string() : id->dump()) + ")";
      const mf::cli::BatchJob job = mf::cli::batch_job_from_json(value);
      run_job(job, settings, &warnings);
      clear_progress();
      print_warnings(warnings, label + ": ");
    } catch (const InputError& e) {
      ++bad;
      clear_progress();
      print_warnings(warnings, label + ": ");
      std::fprintf(stderr, "motionfield: %s: error: %s\n", label.c_str(), e.what());
    } catch (const std::exception& e) {
      ++internal;
      clear_progress();
      std::fprintf(stderr, "motionfield: %s: internal error: %s\n", label.c_str(), e.what());
    }
    ++done;
  }
  clear_progress();
  const int failed = bad + internal;
  if (failed > 0 || settings.verbose || progress)
    std::fprintf(stderr, "motionfield: batch %s: %d jobs, %d ok, %d failed\n", path.c_str(), total, total - failed,
                 failed);
  if (internal > 0) return kExitInternal;
  if (bad > 0) return kExitBadInput;
  return kExitOk;
}

int command_diff(const std::vector<std::string>& args) {
  const CommandArgs a = parse_command_args("diff", args, {"tol", "frames", "step"});
  if (a.help) {
    std::fputs(kDiffHelp, stdout);
    return kExitOk;
  }
  if (a.positional.size() != 2) throw InputError("diff: expected two BVH files (see motionfield diff --help)");
  const double tol = a.has("tol") ? parse_double(a.get("tol"), "--tol") : 1e-4;
  const int step = a.has("step") ? parse_int(a.get("step"), "--step") : 1;
  if (step < 1) throw InputError("diff: --step must be at least 1");
  mf::BvhDocument doc_a, doc_b;
  const mf::BvhUnits units;
  const mf::Motion ma = mf::read_motion(a.positional[0], &doc_a, units);
  const mf::Motion mb = mf::read_motion(a.positional[1], &doc_b, units);

  std::vector<std::string> problems;
  if (ma.skeleton.names != mb.skeleton.names) problems.push_back("joint names differ");
  std::vector<int> frames;
  if (a.has("frames")) {
    frames = parse_int_list(a.get("frames"), "--frames");
  } else {
    for (int f = 0; f < ma.num_frames(); ++f) frames.push_back(f);
  }
  if (!a.has("frames") && !a.has("step")) {
    if (ma.num_frames() != mb.num_frames())
      problems.push_back("frame counts differ: " + std::to_string(ma.num_frames()) + " vs " +
                         std::to_string(mb.num_frames()));
    if (std::abs(doc_a.frame_time - doc_b.frame_time) > 1e-6 * doc_a.frame_time) {
      std::ostringstream s;
      s.precision(9);
      s << "frame times differ: " << doc_a.frame_time << " vs " << doc_b.frame_time;
      problems.push_back(s.str());
    }
  }
  double max_pos = 0, max_rot = 0;
  int worst_pos = -1, worst_rot = -1;
  if (problems.empty()) {
    const int J = ma.num_joints();
    for (int f : frames) {
      const long long g = static_cast<long long>(f) * step;
      if (f < 0 || f >= ma.num_frames() || g >= mb.num_frames()) {
        problems.push_back("frame " + std::to_string(f) + " is out of range");
        break;
      }
      const double d = (ma.root_positions[f] - mb.root_positions[g]).norm() / units.length_scale;
      if (d > max_pos) max_pos = d, worst_pos = f;
      for (int j = 0; j < J; ++j) {
        const double r = mf::geodesic_angle(ma.rotation(f, j), mb.rotation(static_cast<int>(g), j)) * (180.0 / 3.14159265358979323846);
        if (r > max_rot) max_rot = r, worst_rot = f;
      }
    }
  }
  if (problems.empty()) {
    std::printf("compared %zu frames: max root position difference %.3g file units", frames.size(), max_pos);
    if (worst_pos >= 0) std::printf(" (frame %d)", worst_pos);
    std::printf(", max rotation difference %.3g deg", max_rot);
    if (worst_rot >= 0) std::printf(" (frame %d)", worst_rot);
    std::printf("\n");
    if (max_pos > tol) problems.push_back("root positions differ by more than the tolerance");
    if (max_rot > tol) problems.push_back("rotations differ by more than the tolerance");
  }
  for (const std::string& p : problems) std::printf("differ: %s\n", p.c_str());
  return problems.empty() ? kExitOk : kExitDiffer;
}

int run(int argc, char** argv) {
  Settings settings;
  std::vector<std::string> rest;
  bool want_help = false, want_version = false;
  // Global options may appear anywhere; everything else belongs to the command.
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--threads" || a.rfind("--threads=", 0) == 0) {
      std::string value;
      if (a == "--threads") {
        if (i + 1 >= argc) throw InputError("--threads needs a value");
        value = argv[++i];
      } else {
        value = a.substr(10);
      }
      settings.threads = parse_int(value, "--threads");
      if (settings.threads < 1 || settings.threads > 1024)
        throw InputError("--threads must be between 1 and 1024, not " + value);
    } else if (a == "--verbose" || a == "-v") {
      settings.verbose = true;
    } else if (a == "--version") {
      want_version = true;
    } else if ((a == "--help" || a == "-h") && rest.empty()) {
      want_help = true;
    } else {
      rest.push_back(a);
    }
  }
  if (want_version) {
    std::printf("motionfield %s\n", MF_VERSION);
    return kExitOk;
  }
  if (want_help) {
    std::fputs(kMainHelp, stdout);
    return kExitOk;
  }
  if (rest.empty()) {
    std::fputs(kMainHelp, stderr);
    throw InputError("no command given");
  }
  at::set_num_threads(settings.threads);
  if (settings.verbose) std::fprintf(stderr, "motionfield: %d intra-op threads\n", settings.threads);

  const std::string command = rest.front();
  const std::vector<std::string> args(rest.begin() + 1, rest.end());
  if (command == "inbetween" || command == "fill" || command == "resample")
    return command_single(command, args, settings);
  if (command == "batch") return command_batch(args, settings);
  if (command == "diff") return command_diff(args);
  throw InputError("unknown command '" + command + "' (see motionfield --help)");
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const InputError& e) {
    std::fprintf(stderr, "motionfield: error: %s\n", e.what());
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "motionfield: internal error: %s\n", e.what());
    return kExitInternal;
  } catch (...) {
    std::fprintf(stderr, "motionfield: internal error: unknown exception\n");
    return kExitInternal;
  }
}
