// motionfield: the command-line front end (in-betweening, gap filling,
// resampling, re-navigation, batch runs, rig descriptions). It is a client of the C API
// (motionfield.h) and calls nothing else of motionfield; the JSON Lines reading
// (jsonl.h, on nlohmann-json) is its own.
// Exit codes: 0 ok, 2 bad input, 1 internal error; every message goes to
// stderr, prefixed with "motionfield: ".
#include <unistd.h>

#include <charconv>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "capi/cli/jsonl.h"
#include "motionfield.h"
#include "prior/motion/errors.h"  // mf::InputError (header only): the CLI's "bad input"

namespace {

constexpr int kExitOk = 0;
constexpr int kExitInternal = 1;
constexpr int kExitBadInput = 2;
constexpr int kExitDiffer = 3;  // only `motionfield diff`

using mf::InputError;

// ---------------------------------------------------------------- the C API, C++ side

// Throws for a failed C call: bad input (invalid argument, I/O, model, unsupported)
// as InputError (exit 2), anything else as std::runtime_error (exit 1).
void check(int status) {
  if (status == MF_OK) return;
  const std::string message = mf_last_error_message();
  switch (status) {
    case MF_ERROR_INVALID_ARGUMENT:
    case MF_ERROR_IO:
    case MF_ERROR_MODEL:
    case MF_ERROR_UNSUPPORTED:
      throw InputError(message);
    default:
      throw std::runtime_error(std::string(mf_status_name(status)) + ": " + message);
  }
}

struct MotionDeleter {
  void operator()(mf_motion* m) const { mf_motion_destroy(m); }
};
struct ModelDeleter {
  void operator()(mf_model* m) const { mf_model_destroy(m); }
};
using MotionPtr = std::unique_ptr<mf_motion, MotionDeleter>;
using ModelPtr = std::unique_ptr<mf_model, ModelDeleter>;

// Metres per file unit of --units / "units": "" or "auto" = 0 (detected), a
// unit name (mf_length_unit_scale) or a positive number.
double units_scale(const std::string& units, const std::string& what) {
  if (units.empty() || units == "auto") return 0.0;
  double v = 0;
  const auto r = std::from_chars(units.data(), units.data() + units.size(), v);
  if (r.ec == std::errc() && r.ptr == units.data() + units.size()) {
    if (!(std::isfinite(v) && v > 0)) throw InputError(what + " must be positive, not " + units);
    return v;
  }
  if (mf_length_unit_scale(units.c_str(), &v) != MF_OK)
    throw InputError(what + ": " + mf_last_error_message() + "; auto (the default) detects it");
  return v;
}

// Reads a BVH file; `units` as units_scale() takes it.
MotionPtr load_motion(const std::string& path, const std::string& units = "") {
  mf_bvh_options o;
  check(mf_bvh_options_init(&o));
  o.length_scale = units_scale(units, "--units");
  mf_motion* m = nullptr;
  check(mf_motion_load_bvh(path.c_str(), &o, &m));
  return MotionPtr(m);
}

double length_scale_of(const mf_motion* m) {
  double s = 0;
  check(mf_motion_get_length_scale(m, &s));
  return s;
}

int32_t frame_count(const mf_motion* m) {
  int32_t n = 0;
  check(mf_motion_get_frame_count(m, &n));
  return n;
}

int32_t joint_count(const mf_motion* m) {
  int32_t n = 0;
  check(mf_motion_get_joint_count(m, &n));
  return n;
}

double fps_of(const mf_motion* m) {
  double fps = 0;
  check(mf_motion_get_fps(m, &fps));
  return fps;
}

double frame_time_of(const mf_motion* m) {
  double t = 0;
  check(mf_motion_get_frame_time(m, &t));
  return t;
}

std::vector<float> rotations_of(const mf_motion* m) {
  size_t n = 0;
  check(mf_motion_get_rotations(m, nullptr, 0, &n));
  std::vector<float> out(n);
  check(mf_motion_get_rotations(m, out.data(), out.size(), &n));
  return out;
}

std::vector<float> root_positions_of(const mf_motion* m) {
  size_t n = 0;
  check(mf_motion_get_root_positions(m, nullptr, 0, &n));
  std::vector<float> out(n);
  check(mf_motion_get_root_positions(m, out.data(), out.size(), &n));
  return out;
}

std::vector<std::string> joint_names_of(const mf_motion* m) {
  std::vector<std::string> names;
  for (int32_t j = 0, J = joint_count(m); j < J; ++j) {
    size_t n = 0;
    check(mf_motion_get_joint_name(m, j, nullptr, 0, &n));
    std::string name(n, '\0');
    check(mf_motion_get_joint_name(m, j, name.data(), name.size(), &n));
    name.resize(n - 1);
    names.push_back(name);
  }
  return names;
}

struct MethodInfo {
  std::string name, description;
  uint32_t flags = 0;
};

std::vector<MethodInfo> methods() {
  int32_t n = 0;
  check(mf_method_count(&n));
  std::vector<MethodInfo> out;
  for (int32_t i = 0; i < n; ++i) {
    const char* name = nullptr;
    const char* description = nullptr;
    uint32_t flags = 0;
    check(mf_method_get(i, &name, &description, &flags));
    out.push_back({name, description, flags});
  }
  return out;
}

// Flags of a registered method; InputError "unknown method ..." otherwise.
uint32_t method_flags(const std::string& name) {
  int32_t index = 0;
  check(mf_method_find(name.c_str(), &index));
  uint32_t flags = 0;
  check(mf_method_get(index, nullptr, nullptr, &flags));
  return flags;
}

std::string default_method_name(const mf_model* model) {
  const char* name = nullptr;
  check(mf_default_method(model, &name));
  return name;
}

// "  interp     description" lines of the methods that have `flag`, for help texts.
std::string method_list(uint32_t flag) {
  std::string out;
  try {
    for (const MethodInfo& m : methods()) {
      if (!(m.flags & flag)) continue;
      std::string line = "    " + m.name;
      line.resize(std::max<size_t>(line.size() + 1, 14), ' ');
      out += line + m.description + ((m.flags & MF_METHOD_NEEDS_MODEL) ? " [needs the model]" : "") + "\n";
    }
  } catch (const std::exception&) {
  }
  return out;
}

// The model the jobs run with: --model PATH (loaded once, up front), else the
// default model (loaded on first need, when a job names no method, since the
// default method depends on it, or names one that needs the model). The C API
// loads the transformer files next to it; --twostage/--citl PATH add or
// replace them.
class Models {
 public:
  Models(std::string explicit_path, std::vector<std::string> transformers)
      : explicit_path_(std::move(explicit_path)), transformers_(std::move(transformers)) {}

  void load_explicit() {
    if (explicit_path_.empty() || model_) return;
    mf_model* m = nullptr;
    check(mf_model_load(explicit_path_.c_str(), &m));
    model_.reset(m);
    path_ = explicit_path_;
    add_transformers();
  }

  // The model for a job with `method` ("" = the default method): may be null.
  const mf_model* for_method(const std::string& method) {
    if (!explicit_path_.empty()) {
      load_explicit();
      return model_.get();
    }
    const bool needs = !method.empty() && (method_flags(method) & MF_METHOD_NEEDS_MODEL);
    if (!method.empty() && !needs) return nullptr;
    load_default();
    if (needs && !model_)
      throw InputError("method '" + method + "' needs the prior, and no model is loaded (name one with --model)");
    return model_.get();
  }

  // The model, explicit or default, for `what` that always needs it.
  const mf_model* required(const std::string& what) {
    if (!explicit_path_.empty()) {
      load_explicit();
      return model_.get();
    }
    load_default();
    if (!model_) throw InputError(what + " needs the model, and none is installed (name one with --model)");
    return model_.get();
  }

  const std::string& path() const { return path_; }

 private:
  void load_default() {
    if (tried_default_) {
      if (!default_error_.empty()) throw InputError(default_error_);
      return;
    }
    tried_default_ = true;
    size_t n = 0;
    check(mf_model_default_path(nullptr, 0, &n));
    std::string path(n, '\0');
    check(mf_model_default_path(path.data(), path.size(), &n));
    path.resize(n - 1);
    if (path.empty()) return;
    mf_model* m = nullptr;
    const int status = mf_model_load(path.c_str(), &m);
    if (status != MF_OK) {
      default_error_ = std::string("cannot load the default model: ") + mf_last_error_message();
      throw InputError(default_error_);
    }
    model_.reset(m);
    path_ = path;
    add_transformers();
  }

  void add_transformers() {
    for (const std::string& file : transformers_) {
      mf_model* m = nullptr;
      check(mf_model_with_inbetweener(model_.get(), file.c_str(), &m));
      model_.reset(m);
    }
  }

  std::string explicit_path_, path_, default_error_;
  std::vector<std::string> transformers_;
  bool tried_default_ = false;
  ModelPtr model_;
};

// ---------------------------------------------------------------- help texts

const char* kMainHelp =
    "motionfield " MF_VERSION_STRING ": motion in-betweening, gap filling, resampling and re-navigation of BVH clips\n"
    "\n"
    "usage: motionfield [--threads N] [--model PATH] [--twostage PATH] [--citl PATH] [--verbose]\n"
    "                   [--rig-map FILE] [--units U] <command> [options]\n"
    "\n"
    "commands:\n"
    "  inbetween  fill the frames between sparse keyframes\n"
    "  fill       fill a gap of unknown frames\n"
    "  resample   change the frame rate, keeping the time span\n"
    "  renav      make a reference clip follow a new ground path (needs the model)\n"
    "  batch      run many jobs from a JSON Lines file in one process\n"
    "  rig        show how a BVH's rig is read: its unit and its map onto the model's\n"
    "\n"
    "global options:\n"
    "  --threads N    intra-op threads for the solvers (default 2)\n"
    "  --model PATH   the prior's model file (default: the installed model, $MF_MODEL\n"
    "                 or models/motionfield-prior.mfm, if any); needed only by\n"
    "                 methods that use the prior\n"
    "  --twostage PATH, --citl PATH\n"
    "                 transformer in-betweener files (methods context, detail,\n"
    "                 nemf-context, nemf-detail; citl, nemf-citl); default:\n"
    "                 motionfield-twostage.mfm and motionfield-citl.mfm next to\n"
    "                 the model file, when present\n"
    "  --rig-map FILE a JSON map {\"your joint\": \"model joint\" or null} that\n"
    "                 overrides the automatic map of your rig onto the model's\n"
    "  --units U      the BVH length unit: auto (the default: detected from the leg\n"
    "                 length), cm, m, mm, in, ft, asf or metres per unit\n"
    "  --verbose, -v  print what runs and how long it takes (stderr)\n"
    "  --help, -h     this help; `motionfield <command> --help` for a command\n"
    "  --version      print the version\n"
    "\n"
    "Any humanoid rig works, in its own unit and frame rate: methods that need the\n"
    "model retarget it to the model's rig and back (`motionfield rig IN.bvh` shows\n"
    "the map). Output BVH files keep the input's skeleton, channel layout, unit and\n"
    "frame time.\n"
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
    "  --method M        one of the methods below (default: the best available)\n";

const char* kFillHelp =
    "usage: motionfield fill --in IN.bvh --gap A:B --out OUT.bvh [--method M]\n"
    "\n"
    "Frames A..B-1 are unknown and filled; every other frame is kept. The gap must\n"
    "leave at least one known frame on each side: 1 <= A < B <= frames - 1.\n"
    "\n"
    "  --in PATH   input BVH\n"
    "  --gap A:B   the unknown frames, A inclusive, B exclusive\n"
    "  --out PATH  output BVH (written atomically)\n"
    "  --method M  one of the methods below (default: the best available)\n";

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
    "  --method M  one of the methods below (default: the best available)\n";

const char* kRenavHelp =
    "usage: motionfield renav --in REF.bvh (--path PATH.csv | --polyline PATH.csv) --out OUT.bvh\n"
    "                         [--method M] [--fps F] [--frames N]\n"
    "\n"
    "Re-navigation: a motion in the style of the reference clip REF.bvh that follows\n"
    "a new ground path (the prior's latent codes optimised against NeMF's energy: the\n"
    "root path, and soft-DTW divergences of the pose and of the facing relative to\n"
    "the path, against the reference). Needs the model (--model or the default one);\n"
    "the reference may be on any humanoid rig (--rig-map, --units: motionfield --help).\n"
    "\n"
    "The path CSV has one \"x,z\" pair per line, metres, in the BVH's world frame\n"
    "(Y up); an optional header line \"x,z\"; blank lines and lines starting with #\n"
    "are skipped. At least two points, all finite, at least 1 mm long.\n"
    "\n"
    "  --in PATH        reference BVH\n"
    "  --path PATH      one point per output frame: the output has as many frames\n"
    "  --polyline PATH  the vertices of a polyline, walked at constant speed: the\n"
    "                   reference's mean ground speed, or --frames N frames\n"
    "  --out PATH       output BVH (written atomically; the reference's skeleton\n"
    "                   and channel layout)\n"
    "  --method M       nemf (L-BFGS, the default) or nemf-adam (NeMF's Adam\n"
    "                   reference, slower)\n"
    "  --fps F          frame rate of the path's points and of the output\n"
    "                   (default: the reference's)\n"
    "  --frames N       with --polyline: the output's frame count\n"
    "\n"
    "The output starts exactly at the path's first point. Paths longer than the\n"
    "model's window (128 frames) are solved in overlapping windows.\n";

const char* kBatchHelp =
    "usage: motionfield batch JOBS.jsonl\n"
    "\n"
    "Runs one job per line of JOBS.jsonl, each a JSON object:\n"
    "  {\"task\": \"inbetween\", \"in\": \"a.bvh\", \"out\": \"b.bvh\", \"keyframes\": [0, 10, 20]}\n"
    "  {\"task\": \"fill\", \"in\": \"a.bvh\", \"out\": \"c.bvh\", \"gap\": [10, 20]}\n"
    "  {\"task\": \"resample\", \"in\": \"a.bvh\", \"out\": \"d.bvh\", \"fps\": 60, \"method\": \"interp\"}\n"
    "  {\"task\": \"renav\", \"in\": \"a.bvh\", \"out\": \"e.bvh\", \"path\": \"path.csv\"}\n"
    "  {\"task\": \"renav\", \"in\": \"a.bvh\", \"out\": \"f.bvh\", \"polyline\": \"p.csv\", \"frames\": 90}\n"
    "For fill, a \"keyframes\" list, if given, is authoritative over \"gap\". For\n"
    "renav, \"path\" or \"polyline\" and the optional \"fps\" and \"frames\" mean what\n"
    "the flags of `motionfield renav` mean. Every task takes \"rig_map\" (a file) and\n"
    "\"units\" (a name, auto, or metres per unit), which replace --rig-map and\n"
    "--units for that job. Keys a\n"
    "job does not need (\"id\", frame counts, ...) are ignored; blank lines are\n"
    "skipped; relative paths are relative to the current directory. The model\n"
    "(--model) is loaded once for all jobs.\n"
    "A failed job is reported on stderr (line number, id, reason) and the others\n"
    "still run. Exit code: 0 if every job succeeded, 1 if any job hit an internal\n"
    "error, otherwise 2 if any job had bad input. Progress is shown on stderr when\n"
    "it is a terminal.\n";

const char* kRigHelp =
    "usage: motionfield rig IN.bvh [--model PATH] [--rig-map FILE] [--units U] [--json]\n"
    "\n"
    "How the rig of IN.bvh is read and mapped onto the model's (--model or the\n"
    "default one): its length unit (detected from the leg length unless --units\n"
    "names it), which of its joints plays which joint of the model and how that was\n"
    "found (name, shape or map file), and its joints left out (the learned methods\n"
    "interpolate them between known frames). --rig-map FILE entries replace what\n"
    "was found. A rig that cannot be mapped gives the reason (exit 2).\n"
    "\n"
    "  --json  the description as JSON (the C API's mf_rig_describe)\n";

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
  std::string model;
  std::vector<std::string> transformers;  ///< --twostage, --citl
  std::string rig_map;                    ///< --rig-map FILE, "" for the automatic map
  std::string units;                      ///< --units, "" = auto
};

void check_output_path(const std::string& out) {
  namespace fs = std::filesystem;
  const fs::path p(out);
  std::error_code ec;
  if (fs::is_directory(p, ec)) throw InputError("cannot write " + out + ": it is a directory");
  const fs::path dir = p.parent_path();
  if (!dir.empty() && !fs::is_directory(dir, ec))
    throw InputError("cannot write " + out + ": directory " + dir.string() + " does not exist");
}

// The warning of a resampling whose frame count had to be rounded down.
std::string rounding_warning(int frames, double fps_in, double fps_out, int out_frames) {
  std::ostringstream msg;
  const double span_in = (frames - 1) / fps_in, span_out = (out_frames - 1) / fps_out;
  msg << "resampling " << frames << " frames from " << fps_in << " to " << fps_out
      << " fps does not give a whole number of frames (" << (frames - 1) * (fps_out / fps_in) + 1.0
      << "); rounded down to " << out_frames << " frames, so the output ends " << (span_in - span_out)
      << " s before the input's last frame";
  return msg.str();
}

std::vector<float> read_path(const std::string& path) {
  size_t n = 0;
  check(mf_path_load_csv(path.c_str(), nullptr, 0, &n));
  std::vector<float> xz(n);
  check(mf_path_load_csv(path.c_str(), xz.data(), xz.size(), &n));
  return xz;
}

// Runs one job (from the command line or a batch line) end to end: read, solve,
// write. Warnings are appended to *warnings.
void run_job(const mf::cli::BatchJob& job, const Settings& settings, Models& models,
             std::vector<std::string>* warnings) {
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  const bool renav = job.task == "renav";
  // Unknown methods fail before any reading (re-navigation has methods of its own, checked by mf_renav).
  if (!job.method.empty() && !renav) method_flags(job.method);
  if (renav) {
    if (job.fps < 0 || !std::isfinite(job.fps)) throw InputError("renav: the fps must be positive");
    if (job.polyline && job.frames != 0 && job.frames < 2) throw InputError("renav: the frame count must be at least 2");
  }
  check_output_path(job.out);
  // Re-navigation always needs the prior, whatever the method.
  const mf_model* model = models.for_method(renav && job.method.empty() ? "nemf" : job.method);

  const MotionPtr input = load_motion(job.in, job.units.empty() ? settings.units : job.units);
  const int frames_in = frame_count(input.get());
  const std::vector<float> xz = renav ? read_path(job.path_file) : std::vector<float>();
  const auto t1 = Clock::now();

  mf_task_options options;
  check(mf_task_options_init(&options));
  options.method = job.method.empty() ? nullptr : job.method.c_str();
  const std::string& rig_map = job.rig_map.empty() ? settings.rig_map : job.rig_map;
  options.rig_map_path = rig_map.empty() ? nullptr : rig_map.c_str();
  mf_motion* raw = nullptr;
  int32_t expected_frames = frames_in;
  if (job.task == "inbetween" || (job.task == "fill" && job.has_keyframes)) {
    const std::vector<int32_t> keys(job.keyframes.begin(), job.keyframes.end());
    check(mf_inbetween(model, input.get(), keys.data(), keys.size(), &options, &raw));
  } else if (job.task == "fill") {
    check(mf_fill(model, input.get(), job.gap_begin, job.gap_end, &options, &raw));
  } else if (job.task == "resample") {
    const double fps_in = fps_of(input.get());
    int32_t rounded = 0;
    check(mf_resample_frame_count(frames_in, fps_in, job.fps, &expected_frames, &rounded));
    if (rounded && warnings) warnings->push_back(rounding_warning(frames_in, fps_in, job.fps, expected_frames));
    check(mf_resample(model, input.get(), job.fps, &options, &raw));
  } else if (renav) {
    mf_renav_options renav_options;
    check(mf_renav_options_init(&renav_options));
    renav_options.path_kind = job.polyline ? MF_PATH_POLYLINE : MF_PATH_PER_FRAME;
    if (job.fps > 0) renav_options.fps = job.fps;
    if (job.polyline) renav_options.frame_count = job.frames;
    check(mf_renav(model, input.get(), xz.data(), xz.size() / 2, &renav_options, &options, &raw));
    expected_frames = job.polyline ? renav_options.frame_count : static_cast<int32_t>(xz.size() / 2);
  } else {
    throw InputError("unknown task '" + job.task + "'");
  }
  const MotionPtr result(raw);
  const auto t2 = Clock::now();

  const int32_t frames_out = frame_count(result.get());
  if (expected_frames > 0 && frames_out != expected_frames)
    throw std::logic_error("the result has " + std::to_string(frames_out) + " frames, expected " +
                           std::to_string(expected_frames));
  check(mf_motion_save_bvh(result.get(), job.out.c_str(), nullptr));
  const auto t3 = Clock::now();

  if (settings.verbose) {
    auto ms = [](Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); };
    const std::string method = !job.method.empty()      ? job.method
                               : job.task == "resample" ? std::string("default")
                               : renav                  ? std::string("nemf")
                                                        : default_method_name(model);
    std::fprintf(stderr,
                 "motionfield: %s %s -> %s: %d -> %d frames, method %s, model %s, %d threads; read %.1f ms, "
                 "solve %.1f ms, write %.1f ms\n",
                 job.task.c_str(), job.in.c_str(), job.out.c_str(), frames_in, frames_out, method.c_str(),
                 model ? models.path().c_str() : "none", settings.threads, ms(t1 - t0), ms(t2 - t1), ms(t3 - t2));
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
    std::printf("\nmethods:\n%s",
                method_list(command == "resample" ? MF_METHOD_RESAMPLES : MF_METHOD_COMPLETES).c_str());
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
  Models models(settings.model, settings.transformers);
  models.load_explicit();
  std::vector<std::string> warnings;
  run_job(job, settings, models, &warnings);
  print_warnings(warnings, "");
  return kExitOk;
}

int command_renav(const std::vector<std::string>& args, const Settings& settings) {
  const CommandArgs a = parse_command_args("renav", args, {"in", "out", "method", "path", "polyline", "fps", "frames"});
  if (a.help) {
    std::fputs(kRenavHelp, stdout);
    return kExitOk;
  }
  if (!a.positional.empty())
    throw InputError("renav: unexpected argument '" + a.positional.front() + "' (see motionfield renav --help)");
  mf::cli::BatchJob job;
  job.task = "renav";
  job.in = a.required("in", "renav");
  job.out = a.required("out", "renav");
  if (a.has("path") == a.has("polyline"))
    throw InputError("renav: give exactly one of --path and --polyline (see motionfield renav --help)");
  job.polyline = a.has("polyline");
  job.path_file = a.get(job.polyline ? "polyline" : "path");
  if (a.has("method")) {
    job.method = a.get("method");
    if (job.method.empty()) throw InputError("renav: --method needs a value");
  }
  if (a.has("fps")) {
    job.fps = parse_double(a.get("fps"), "--fps");
    if (!(job.fps > 0)) throw InputError("renav: --fps must be positive");
  }
  if (a.has("frames")) {
    if (!job.polyline) throw InputError("renav: --frames goes with --polyline (a --path has one point per frame)");
    job.frames = parse_int(a.get("frames"), "--frames");
    if (job.frames < 2) throw InputError("renav: --frames must be at least 2");
  }
  Models models(settings.model, settings.transformers);
  models.load_explicit();
  std::vector<std::string> warnings;
  run_job(job, settings, models, &warnings);
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

  Models models(settings.model, settings.transformers);
  models.load_explicit();
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
      run_job(job, settings, models, &warnings);
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

std::string read_text_file(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the " + what);
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw InputError(path + ": cannot read the " + what);
  return text.str();
}

// The text form of mf_rig_describe's JSON.
void print_rig(const std::string& in, const mf::cli::JsonValue& d, const std::string& model_path, bool units_given) {
  const bool detected = d.find("unit_detected")->as_bool();
  const char* unit_how = units_given ? "given" : detected ? "detected from the leg length" : "no legs found: assumed";
  std::printf("%s: %d joints, unit %s (%s; %g m per file unit)\n", in.c_str(),
              static_cast<int>(d.find("joints")->as_number()), d.find("unit")->as_string().c_str(), unit_how,
              d.find("length_scale")->as_number());
  std::printf("mapped onto %s (%zu joints): user joint -> model joint, found by\n", model_path.c_str(),
              d.find("model_joints")->as_array().size());
  const mf::cli::JsonValue& map = *d.find("map");
  const mf::cli::JsonValue& how = *d.find("how");
  size_t width = 0;
  for (const std::string& user : map.keys()) width = std::max(width, user.size());
  for (size_t i = 0; i < map.keys().size(); ++i) {
    const std::string& model_joint = map.values()[i].as_string();
    std::printf("  %-*s -> %-14s %s\n", static_cast<int>(width), map.keys()[i].c_str(), model_joint.c_str(),
                how.find(model_joint)->as_string().c_str());
  }
  std::string left;
  for (const mf::cli::JsonValue& j : d.find("unmapped_user_joints")->as_array())
    left += (left.empty() ? "" : ", ") + j.as_string();
  std::printf("user joints left out: %s\n", left.empty() ? "none" : left.c_str());
  if (!d.find("retargeting")->as_bool())
    std::printf("note: the model has no rig anatomy (motionfield-rig.json next to it): "
                "only its own rig can be solved\n");
}

int command_rig(std::vector<std::string> args, const Settings& settings) {
  const auto json_flag = std::find(args.begin(), args.end(), "--json");
  const bool json = json_flag != args.end();
  if (json) args.erase(json_flag);
  const CommandArgs a = parse_command_args("rig", args, {});
  if (a.help) {
    std::fputs(kRigHelp, stdout);
    return kExitOk;
  }
  if (a.positional.size() != 1) throw InputError("rig: expected exactly one BVH file (see motionfield rig --help)");
  const std::string& in = a.positional.front();
  const std::string map = settings.rig_map.empty() ? "" : read_text_file(settings.rig_map, "rig map file");
  Models models(settings.model, settings.transformers);
  const mf_model* model = models.required("rig");
  const MotionPtr motion = load_motion(in, settings.units);
  size_t n = 0;
  int status = mf_rig_describe(model, motion.get(), map.c_str(), nullptr, 0, &n);
  std::string text(n, '\0');
  if (status == MF_OK) status = mf_rig_describe(model, motion.get(), map.c_str(), text.data(), text.size(), &n);
  if (status == MF_ERROR_INVALID_ARGUMENT && !settings.rig_map.empty())
    throw InputError(settings.rig_map + ": " + mf_last_error_message());
  check(status);
  text.resize(n - 1);
  if (json) {
    std::printf("%s\n", text.c_str());
  } else {
    print_rig(in, mf::cli::parse_json(text), models.path(), units_scale(settings.units, "--units") > 0);
  }
  return kExitOk;
}

// Angle in degrees between two rotations given as (w, x, y, z) floats: the
// angle of q_a^-1 q_b, computed from its vector part (accurate near zero).
double rotation_difference_degrees(const float* a, const float* b) {
  double qa[4], qb[4], na = 0, nb = 0;
  for (int k = 0; k < 4; ++k) {
    qa[k] = a[k], qb[k] = b[k];
    na += qa[k] * qa[k], nb += qb[k] * qb[k];
  }
  na = std::sqrt(na), nb = std::sqrt(nb);
  for (int k = 0; k < 4; ++k) qa[k] /= na, qb[k] /= nb;
  // r = conj(qa) * qb
  const double w = qa[0] * qb[0] + qa[1] * qb[1] + qa[2] * qb[2] + qa[3] * qb[3];
  const double x = qa[0] * qb[1] - qa[1] * qb[0] - qa[2] * qb[3] + qa[3] * qb[2];
  const double y = qa[0] * qb[2] + qa[1] * qb[3] - qa[2] * qb[0] - qa[3] * qb[1];
  const double z = qa[0] * qb[3] - qa[1] * qb[2] + qa[2] * qb[1] - qa[3] * qb[0];
  const double angle = 2.0 * std::atan2(std::sqrt(x * x + y * y + z * z), std::abs(w));
  return angle * (180.0 / 3.14159265358979323846);
}

int command_diff(const std::vector<std::string>& args, const Settings& settings) {
  const CommandArgs a = parse_command_args("diff", args, {"tol", "frames", "step"});
  if (a.help) {
    std::fputs(kDiffHelp, stdout);
    return kExitOk;
  }
  if (a.positional.size() != 2) throw InputError("diff: expected two BVH files (see motionfield diff --help)");
  const double tol = a.has("tol") ? parse_double(a.get("tol"), "--tol") : 1e-4;
  const int step = a.has("step") ? parse_int(a.get("step"), "--step") : 1;
  if (step < 1) throw InputError("diff: --step must be at least 1");
  const MotionPtr ma = load_motion(a.positional[0], settings.units);
  const MotionPtr mb = load_motion(a.positional[1], settings.units);
  const double file_units_per_metre = 1.0 / length_scale_of(ma.get());
  const int frames_a = frame_count(ma.get()), frames_b = frame_count(mb.get());

  std::vector<std::string> problems;
  if (joint_names_of(ma.get()) != joint_names_of(mb.get())) problems.push_back("joint names differ");
  std::vector<int> frames;
  if (a.has("frames")) {
    frames = parse_int_list(a.get("frames"), "--frames");
  } else {
    for (int f = 0; f < frames_a; ++f) frames.push_back(f);
  }
  if (!a.has("frames") && !a.has("step")) {
    if (frames_a != frames_b)
      problems.push_back("frame counts differ: " + std::to_string(frames_a) + " vs " + std::to_string(frames_b));
    const double ta = frame_time_of(ma.get()), tb = frame_time_of(mb.get());
    if (std::abs(ta - tb) > 1e-6 * ta) {
      std::ostringstream s;
      s.precision(9);
      s << "frame times differ: " << ta << " vs " << tb;
      problems.push_back(s.str());
    }
  }
  double max_pos = 0, max_rot = 0;
  int worst_pos = -1, worst_rot = -1;
  if (problems.empty()) {
    const int J = joint_count(ma.get());
    const std::vector<float> rot_a = rotations_of(ma.get()), rot_b = rotations_of(mb.get());
    const std::vector<float> pos_a = root_positions_of(ma.get()), pos_b = root_positions_of(mb.get());
    for (int f : frames) {
      const long long g = static_cast<long long>(f) * step;
      if (f < 0 || f >= frames_a || g >= frames_b) {
        problems.push_back("frame " + std::to_string(f) + " is out of range");
        break;
      }
      double d2 = 0;
      for (int k = 0; k < 3; ++k) {
        const double d = static_cast<double>(pos_a[3 * f + k]) - pos_b[3 * g + k];
        d2 += d * d;
      }
      const double d = std::sqrt(d2) * file_units_per_metre;
      if (d > max_pos) max_pos = d, worst_pos = f;
      for (int j = 0; j < J; ++j) {
        const double r = rotation_difference_degrees(&rot_a[4 * (static_cast<size_t>(f) * J + j)],
                                                     &rot_b[4 * (static_cast<size_t>(g) * J + j)]);
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

// Value of a global option given as "--name VALUE" or "--name=VALUE" at argv[*i].
bool global_option(int argc, char** argv, int* i, const std::string& name, std::string* value) {
  const std::string a = argv[*i];
  const std::string flag = "--" + name;
  if (a == flag) {
    if (*i + 1 >= argc) throw InputError(flag + " needs a value");
    *value = argv[++*i];
    return true;
  }
  if (a.rfind(flag + "=", 0) == 0) {
    *value = a.substr(flag.size() + 1);
    return true;
  }
  return false;
}

int run(int argc, char** argv) {
  Settings settings;
  std::vector<std::string> rest;
  bool want_help = false, want_version = false, have_model = false;
  // Global options may appear anywhere; everything else belongs to the command.
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    std::string value;
    if (global_option(argc, argv, &i, "threads", &value)) {
      settings.threads = parse_int(value, "--threads");
      if (settings.threads < 1 || settings.threads > 1024)
        throw InputError("--threads must be between 1 and 1024, not " + value);
    } else if (global_option(argc, argv, &i, "model", &value)) {
      if (have_model) throw InputError("--model is given more than once");
      if (value.empty()) throw InputError("--model needs a value");
      settings.model = value;
      have_model = true;
    } else if (global_option(argc, argv, &i, "twostage", &value) || global_option(argc, argv, &i, "citl", &value)) {
      if (value.empty()) throw InputError(a + " needs a value");
      settings.transformers.push_back(value);
    } else if (global_option(argc, argv, &i, "rig-map", &value)) {
      if (value.empty()) throw InputError("--rig-map needs a value");
      settings.rig_map = value;
    } else if (global_option(argc, argv, &i, "units", &value)) {
      units_scale(value, "--units");
      settings.units = value;
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
    std::printf("motionfield %s\n", mf_version_string());
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
  check(mf_set_num_threads(settings.threads));
  if (settings.verbose) std::fprintf(stderr, "motionfield: %d intra-op threads\n", settings.threads);

  const std::string command = rest.front();
  const std::vector<std::string> args(rest.begin() + 1, rest.end());
  if (command == "inbetween" || command == "fill" || command == "resample")
    return command_single(command, args, settings);
  if (command == "renav") return command_renav(args, settings);
  if (command == "batch") return command_batch(args, settings);
  if (command == "diff") return command_diff(args, settings);
  if (command == "rig") return command_rig(args, settings);
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
