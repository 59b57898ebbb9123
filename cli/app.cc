#include "app.h"

#include <algorithm>
#include <climits>
#include <exception>
#include <map>
#include <memory>

#include "motionfield.hpp"

namespace motionfield::cli {
namespace {

// CLI11's help in motionfield's layout: "usage: ..." and the command's text
// first, then the options, then the footer. The one-line description of a
// command is what the main help lists.
class HelpFormatter : public CLI::Formatter {
 public:
  void set_text(const CLI::App* app, std::string usage, std::string text) {
    texts_[app] = {std::move(usage), std::move(text)};
  }
  std::string make_description(const CLI::App*) const override { return ""; }
  std::string make_usage(const CLI::App* app, std::string) const override {
    const auto it = texts_.find(app);
    if (it == texts_.end()) return "";
    return "usage: " + it->second.usage + "\n\n" + it->second.text + "\n";
  }

 private:
  struct Text {
    std::string usage, text;
  };
  std::map<const CLI::App*, Text> texts_;
};

// "    interp      description" lines of the methods that have `flag`.
std::string method_list(uint32_t flag) {
  std::string out = "methods:\n";
  try {
    for (const MethodInfo& m : methods()) {
      if (!(m.flags & flag)) continue;
      std::string line = "    " + m.name;
      line.resize(std::max<size_t>(line.size() + 1, 14), ' ');
      out += line + m.description + (m.needs_model() ? " [needs the model]" : "") + "\n";
    }
  } catch (const std::exception&) {
    // Help without the list rather than no help.
  }
  return out;
}

const char* kGlobalOptionsNote = "Global options (--threads, --model, --rig-map, --units, ...): motionfield --help.";

CLI::App* add_command(CLI::App& app, HelpFormatter& help, const std::string& name, const std::string& summary,
                      const std::string& usage, const std::string& text) {
  CLI::App* cmd = app.add_subcommand(name, summary);
  cmd->group("commands");
  cmd->option_defaults()->group("options");
  cmd->set_help_flag("-h,--help", "this help");
  help.set_text(cmd, usage, text);
  return cmd;
}

// A validator whose description stays out of the help's option column.
CLI::Validator quiet(CLI::Validator check) { return check.description(""); }

// An empty value (--model "") would silently mean the default: refuse it.
const CLI::Validator kNonEmpty(
    [](const std::string& value) { return value.empty() ? std::string("needs a value") : std::string(); }, "");

// --in and --out of the task commands.
void add_task_files(CLI::App* cmd, JobOptions& job, const std::string& in_help) {
  cmd->add_option("-i,--in", job.in, in_help + "; - reads standard input")->required()->type_name("PATH");
  cmd->add_option("-o,--out", job.out,
                  "output: BVH, or glTF 2.0 for a name ending in .glb\n(binary) or .gltf (JSON); a file is replaced "
                  "atomically,\na device or FIFO written in place; - writes BVH to\nstandard output")
      ->required()
      ->type_name("PATH");
}

void add_method(CLI::App* cmd, JobOptions& job,
                const std::string& help = "one of the methods below (default: the best available)") {
  cmd->add_option("--method", job.method, help)->type_name("M")->check(kNonEmpty);
  cmd->add_option("--max-iterations", job.max_iterations,
                  "iteration budget of the iterative methods per window (the\nlatent solvers' full-energy stage, "
                  "prior resampling,\nre-navigation); 0, the default, is each method's own.\nFewer are faster and "
                  "rougher (0..100000; docs/BENCHMARKS.md, Iteration caps)")
      ->type_name("N")
      ->check(quiet(CLI::Range(0, 100000)));
}

// --constraints, --alternatives and --report of inbetween, fill and transition.
void add_constraints(CLI::App* cmd, JobOptions& job) {
  cmd->add_option("--constraints", job.constraints_file,
                  "a constraints file (JSON, docs/CONSTRAINTS.md): partial keys,\nend-effector targets, contacts")
      ->type_name("FILE")
      ->check(kNonEmpty);
  cmd->add_option("--trajectory", job.trajectory_file,
                  "a trajectory CSV (frame,x,z,forward_x,forward_z per frame,\ndocs/CONSTRAINTS.md) the root follows (latent solvers)")
      ->type_name("FILE")
      ->check(kNonEmpty);
  cmd->add_option("--alternatives", job.alternatives,
                  "N more solutions, written beside the output as\nOUT_1.bvh .. OUT_N.bvh (0..16)")
      ->type_name("N")
      ->check(quiet(CLI::Range(0, 16)));
  cmd->add_option("--report", job.report_file,
                  "write how well each solution meets the constraints\n(JSON) to FILE")
      ->type_name("FILE")
      ->check(kNonEmpty);
  cmd->add_flag("--no-fallback", job.no_fallback,
                "keep the latent solvers' result where their fit to the keys\nis poor (by default such a window is "
                "interpolated, with a\nwarning; docs/API.md, When the prior cannot reach the keys)");
}

void define_global_options(CLI::App& app, Settings& s, bool& version_flag) {
  app.option_defaults()->group("global options");
  app.set_help_flag("-h,--help", "this help; `motionfield <command> --help` for a command");
  app.add_option("--threads", s.threads, "intra-op threads of each job: the BLAS's pool for its\nmatrix products (default 1; batch jobs side by side use\nthe cores better)")
      ->type_name("N")
      ->check(quiet(CLI::Range(1, 1024)));
  app.add_option("--model", s.model,
                 "the prior's model file (default: the installed model,\n$MF_MODEL or models/motionfield-prior.mfm, "
                 "if any);\nneeded only by methods that use the prior")
      ->type_name("PATH")
      ->check(kNonEmpty);
  const char* transformer_help =
      "transformer in-betweener files (methods context, detail,\nnemf-context, nemf-detail; citl, nemf-citl); "
      "default:\nmotionfield-twostage.mfm and motionfield-citl.mfm next to\nthe model file, when present";
  app.add_option("--twostage", s.twostage, transformer_help)
      ->type_name("PATH")
      ->allow_extra_args(false)
      ->check(kNonEmpty);
  app.add_option("--citl", s.citl, "the same")->type_name("PATH")->allow_extra_args(false)->check(kNonEmpty);
  app.add_option("--rig-map", s.rig_map,
                 "a JSON map {\"your joint\": \"model joint\" or null} that\noverrides the automatic map of your rig "
                 "onto the model's")
      ->type_name("FILE")
      ->check(kNonEmpty);
  app.add_option("--units,--length-scale", s.units,
                 "the BVH length unit: auto (the default: detected from the\nleg length), cm, m, mm, in, ft, asf or "
                 "metres per unit\n(--length-scale 0.01 = --units cm)")
      ->type_name("U");
  app.add_option("--animation", s.animation,
                 "the animation of a glTF or FBX input to read, by name or\nindex (default: the first)")
      ->type_name("NAME|INDEX")
      ->check(kNonEmpty);
  app.add_flag("-v,--verbose", s.verbose, "print what runs and how long it takes (stderr)");
  app.add_flag("-q,--quiet", s.quiet, "no progress bar and no warnings (errors are still printed)");
  app.add_flag("--json", s.json,
               "print a JSON summary of each job on stdout, one object per\nline (method, frames, timings, "
               "warnings; rig: the\ndescription)");
  app.add_flag("--version", version_flag, "print the versions of the program, the library, its ABI\nand the "
                                           "model (--model or the default one)");
}

void define_inbetween(CLI::App& app, HelpFormatter& help, Arguments& a) {
  CLI::App* cmd = add_command(app, help, "inbetween", "fill the frames between sparse keyframes",
                              "motionfield inbetween --in IN.bvh --keyframes K0,K1,... --out OUT.bvh [--method M]",
                              "Keeps the keyframes (0-based frame indices, strictly increasing, at least two)\n"
                              "and fills every other frame. Frames before the first and after the last\n"
                              "keyframe hold that keyframe. The output has the input's length.");
  add_task_files(cmd, a.job, "input BVH");
  cmd->add_option("--keyframes", a.keyframes, "comma-separated frame indices, e.g. 0,10,20,29")
      ->required()
      ->type_name("LIST");
  add_method(cmd, a.job);
  add_constraints(cmd, a.job);
  cmd->footer([] { return method_list(MF_METHOD_COMPLETES) + "\n" + kGlobalOptionsNote; });
}

void define_fill(CLI::App& app, HelpFormatter& help, Arguments& a) {
  CLI::App* cmd = add_command(app, help, "fill", "fill a gap of unknown frames",
                              "motionfield fill --in IN.bvh --gap A:B --out OUT.bvh [--method M]",
                              "Frames A..B-1 are unknown and filled; every other frame is kept. The gap must\n"
                              "leave at least one known frame on each side: 1 <= A < B <= frames - 1.");
  add_task_files(cmd, a.job, "input BVH");
  cmd->add_option("--gap", a.gap, "the unknown frames, A inclusive, B exclusive")->required()->type_name("A:B");
  add_method(cmd, a.job);
  add_constraints(cmd, a.job);
  cmd->footer([] { return method_list(MF_METHOD_COMPLETES) + "\n" + kGlobalOptionsNote; });
}

void define_resample(CLI::App& app, HelpFormatter& help, Arguments& a) {
  CLI::App* cmd = add_command(app, help, "resample", "change the frame rate, keeping the time span",
                              "motionfield resample --in IN.bvh --fps F --out OUT.bvh [--method M]",
                              "Resamples to F frames per second keeping the time span: N frames at f_in give\n"
                              "(N-1)*F/f_in + 1 frames at F. A non-integer count is rounded down (with a\n"
                              "warning on stderr). The output's frame time is 1/F.");
  add_task_files(cmd, a.job, "input BVH");
  cmd->add_option("--fps", a.job.fps, "target frame rate, e.g. 60")->required()->type_name("F");
  add_method(cmd, a.job);
  cmd->footer([] { return method_list(MF_METHOD_RESAMPLES) + "\n" + kGlobalOptionsNote; });
}

void define_renav(CLI::App& app, HelpFormatter& help, Arguments& a) {
  CLI::App* cmd = add_command(app, help, "renav", "make a reference clip follow a new ground path (needs the model)",
                              "motionfield renav --in REF.bvh (--path PATH.csv | --polyline PATH.csv) --out OUT.bvh\n"
                              "                         [--method M] [--fps F] [--frames N]",
                              "Re-navigation: a motion in the style of the reference clip REF.bvh that follows\n"
                              "a new ground path (the prior's latent codes optimised against NeMF's energy: the\n"
                              "root path, and soft-DTW divergences of the pose and of the facing relative to\n"
                              "the path, against the reference). Needs the model (--model or the default one);\n"
                              "the reference may be on any humanoid rig (--rig-map, --units: motionfield --help).\n"
                              "\n"
                              "The path CSV has one \"x,z\" pair per line, metres, in the BVH's world frame\n"
                              "(Y up); an optional header line \"x,z\"; blank lines and lines starting with #\n"
                              "are skipped. At least two points, all finite, at least 1 mm long.");
  add_task_files(cmd, a.job, "reference BVH");
  CLI::Option* path =
      cmd->add_option("--path", a.path,
                      "one point per output frame: the output has as many frames; a\n"
                      "path walked faster or slower than the reference plays the\n"
                      "reference at the path's pace (at most 2x)")
          ->type_name("PATH");
  CLI::Option* polyline = cmd->add_option("--polyline", a.polyline,
                                          "the vertices of a polyline, walked at constant speed: the\n"
                                          "reference's mean ground speed, or --frames N frames")
                              ->type_name("PATH");
  path->excludes(polyline);
  add_method(cmd, a.job, "nemf (L-BFGS, the default) or nemf-adam (NeMF's Adam\nreference, slower)");
  cmd->add_option("--fps", a.job.fps, "frame rate of the path's points and of the output\n(default: the reference's)")
      ->type_name("F")
      ->check(quiet(CLI::PositiveNumber));
  cmd->add_option("--frames", a.job.frames, "with --polyline: the output's frame count")
      ->type_name("N")
      ->check(quiet(CLI::Range(2, INT_MAX)))
      ->needs(polyline);
  cmd->footer(std::string("The output starts exactly at the path's first point. Paths longer than the\n"
                          "model's window (128 frames) are solved in overlapping windows.\n\n") +
              kGlobalOptionsNote);
}

void define_transition(CLI::App& app, HelpFormatter& help, Arguments& a) {
  CLI::App* cmd = add_command(
      app, help, "transition", "generate the frames between the end of one clip and the start of another",
      "motionfield transition A B -o OUT [--frames N] [--from-frame I] [--to-frame J]\n"
      "                              [--place auto|keep] [--only-transition] [--method M]",
      "One clip out of two: A's frames 0..I, N generated frames, B's frames J.. (on\n"
      "A's rig, unit and frame rate; B may list the same joints in another order or\n"
      "name them otherwise on the same hierarchy, and is resampled to A's rate).\n"
      "--place auto moves and turns B on the ground so that it continues A's end\n"
      "(facing alike, the root carried on at the mean of the two clips' speeds at the\n"
      "seams); keep leaves B where it is. Without --frames, N is chosen from the change\n"
      "of pose (and with keep the distance between the clips), 10..60 frames at 30\n"
      "fps, and reported. Constraint frames (--constraints, --trajectory) are frames\n"
      "of the whole output clip.");
  cmd->add_option("a", a.job.in, "clip A (BVH, glTF or FBX): its end is kept")->required()->type_name("A");
  cmd->add_option("b", a.to, "clip B: its start is kept")->required()->type_name("B");
  cmd->add_option("-o,--out", a.job.out, "output: BVH, or glTF 2.0 for a name ending in .glb or .gltf;\n- writes BVH to standard output")
      ->required()
      ->type_name("PATH");
  cmd->add_option("--frames", a.job.frames, "generated frames N (1..600; default: chosen)")
      ->type_name("N")
      ->check(quiet(CLI::Range(1, 600)));
  cmd->add_option("--from-frame", a.from_frame, "A's last kept frame (default: its last; negative counts\nfrom the end)")
      ->type_name("I");
  cmd->add_option("--to-frame", a.to_frame, "B's first kept frame (default 0; negative counts from the\nend)")
      ->type_name("J");
  cmd->add_option("--place", a.place, "auto (default): B continues A's end; keep: B stays put")
      ->type_name("auto|keep")
      ->check(quiet(CLI::IsMember({"auto", "keep"})));
  cmd->add_flag("--only-transition", a.only_transition, "write only the N generated frames");
  add_method(cmd, a.job);
  add_constraints(cmd, a.job);
  cmd->footer([] { return method_list(MF_METHOD_COMPLETES) + "\n" + kGlobalOptionsNote; });
}

void define_export(CLI::App& app, HelpFormatter& help, Arguments& a) {
  CLI::App* cmd = add_command(app, help, "export", "write a BVH clip as glTF 2.0 (.glb or .gltf)",
                              "motionfield export IN.bvh OUT.glb|OUT.gltf [--units U]",
                              "Writes the motion of IN.bvh as glTF 2.0: a skin-less armature (one node per\n"
                              "joint, named after it, its rest offset as translation) and one animation with\n"
                              "every joint's rotation and the root's translation at each frame time. Metres\n"
                              "(the BVH's unit is detected from the leg length unless --units names it),\n"
                              "seconds, Y up. OUT.glb is binary, OUT.gltf JSON with the buffer embedded\n"
                              "(base64); any other name is written as BVH. The task commands write glTF the\n"
                              "same way: -o OUT.glb.");
  cmd->add_option("in", a.job.in, "the BVH file; - reads standard input")->required()->type_name("IN.bvh");
  cmd->add_option("out", a.job.out, "the output file: .glb or .gltf")->required()->type_name("OUT.glb");
  cmd->footer(kGlobalOptionsNote);
}

void define_batch(CLI::App& app, HelpFormatter& help, Arguments& a) {
  CLI::App* cmd = add_command(
      app, help, "batch", "run many jobs from a JSON Lines file in one process",
      "motionfield batch JOBS.jsonl [--jobs N]",
      "Runs one job per line of JOBS.jsonl, each a JSON object:\n"
      "  {\"task\": \"inbetween\", \"in\": \"a.bvh\", \"out\": \"b.bvh\", \"keyframes\": [0, 10, 20]}\n"
      "  {\"task\": \"fill\", \"in\": \"a.bvh\", \"out\": \"c.bvh\", \"gap\": [10, 20]}\n"
      "  {\"task\": \"resample\", \"in\": \"a.bvh\", \"out\": \"d.bvh\", \"fps\": 60, \"method\": \"interp\"}\n"
      "  {\"task\": \"renav\", \"in\": \"a.bvh\", \"out\": \"e.bvh\", \"path\": \"path.csv\"}\n"
      "  {\"task\": \"renav\", \"in\": \"a.bvh\", \"out\": \"f.bvh\", \"polyline\": \"p.csv\", \"frames\": 90}\n"
      "  {\"task\": \"transition\", \"in\": \"a.bvh\", \"to\": \"b.bvh\", \"out\": \"g.bvh\", \"frames\": 20}\n"
      "For fill, a \"keyframes\" list, if given, is authoritative over \"gap\". For\n"
      "renav, \"path\" or \"polyline\" and the optional \"fps\" and \"frames\" mean what\n"
      "the flags of `motionfield renav` mean. A transition takes \"to\" (clip B),\n"
      "\"frames\", \"from_frame\", \"to_frame\", \"place\" and \"only_transition\" as the\n"
      "arguments of `motionfield transition`. inbetween, fill and transition take \"constraints\"\n"
      "(a file or an inline object), \"trajectory\" (a CSV file), \"alternatives\" and\n"
      "\"report\" as the flags --constraints, --trajectory, --alternatives and --report,\n"
      "and \"fallback\": false as the flag --no-fallback.\n"
      "Every task takes \"max_iterations\" as the flag --max-iterations, and\n"
      "\"rig_map\" (a file) and\n"
      "\"units\" (a name, auto, or metres per unit), which replace --rig-map and\n"
      "--units for that job. Keys a job does not need (\"id\", frame counts, ...) are\n"
      "ignored; blank lines are skipped; relative paths are relative to the current\n"
      "directory. The model (--model) is loaded once for all jobs.\n"
      "A job may not write the output of an earlier line, nor its own input; \"-\"\n"
      "(standard input or output) is for single commands only.\n"
      "A failed job is reported on stderr (line number, id, reason) and the others\n"
      "still run. Exit code: 0 if every job succeeded, 1 if any job hit an internal\n"
      "error, otherwise 2 if any job had bad input. Progress is shown on stderr when\n"
      "it is a terminal (with more than one job at once: how many jobs are done).\n"
      "--jobs N runs N jobs at once on the one model (threads; each job still uses\n"
      "--threads intra-op threads): the outputs and messages are those of a serial\n"
      "run, in line order. Without --jobs: the processor's cores divided by\n"
      "--threads, at least 1 and at most 8.");
  cmd->add_option("jobs", a.file, "the jobs, one JSON object per line")->required()->type_name("JOBS.jsonl");
  cmd->add_option("-j,--jobs", a.settings.jobs, "jobs run at once (default: cores / --threads, 1 to 8)")
      ->check(CLI::Range(1, 256))
      ->type_name("N");
  cmd->footer(kGlobalOptionsNote);
}

void define_rig(CLI::App& app, HelpFormatter& help, Arguments& a) {
  CLI::App* cmd = add_command(app, help, "rig", "show how a BVH's rig is read: its unit and its map onto the model's",
                              "motionfield rig IN.bvh [--model PATH] [--rig-map FILE] [--units U] [--json]",
                              "How the rig of IN.bvh is read and mapped onto the model's (--model or the\n"
                              "default one): its length unit (detected from the leg length unless --units\n"
                              "names it), which of its joints plays which joint of the model and how that was\n"
                              "found (name, shape or map file), and its joints left out (the learned methods\n"
                              "interpolate them between known frames). --rig-map FILE entries replace what\n"
                              "was found. A rig that cannot be mapped gives the reason (exit 2).");
  cmd->add_option("in", a.file, "the BVH file")->required()->type_name("IN.bvh");
  cmd->footer(kGlobalOptionsNote);
}

}  // namespace

void define_command_line(CLI::App& app, Arguments& args) {
  auto help = std::make_shared<HelpFormatter>();
  help->column_width(22);
  app.formatter(help);  // before the commands: they share it
  help->set_text(
      &app,
      "motionfield [--threads N] [--model PATH] [--twostage PATH] [--citl PATH] [--verbose]\n"
      "                   [--quiet] [--json] [--rig-map FILE] [--units U] <command> [options]",
      "motionfield " + version() + ": motion in-betweening, gap filling, transitions, resampling and re-navigation of BVH clips");
  // Global options may come anywhere, also after the command.
  app.fallthrough();
  define_global_options(app, args.settings, args.version);
  define_inbetween(app, *help, args);
  define_fill(app, *help, args);
  define_resample(app, *help, args);
  define_renav(app, *help, args);
  define_transition(app, *help, args);
  define_export(app, *help, args);
  define_batch(app, *help, args);
  define_rig(app, *help, args);
  app.footer(
      "Any humanoid rig works, in its own unit and frame rate: methods that need the\n"
      "model retarget it to the model's rig and back (`motionfield rig IN.bvh` shows\n"
      "the map). Output BVH files keep the input's skeleton, channel layout, unit and\n"
      "frame time; outputs named .glb or .gltf are glTF 2.0 in metres (motionfield\n"
      "export --help).\n"
      "A progress bar (iterations, windows, time left) is drawn on stderr when it is a\n"
      "terminal, unless --quiet. Messages quote file names and input with control\n"
      "characters escaped.\n"
      "Exit codes: 0 ok, 2 bad input (message on stderr), 1 internal error.");
}

}  // namespace motionfield::cli
