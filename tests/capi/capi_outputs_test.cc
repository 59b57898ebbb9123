// The one safe writer (mf_output_set_*, mf_motion_save_*): outputs never
// overwrite each other or an input, devices are written in place, a failure
// names its reason and leaves nothing behind, temporary names are unique; and
// the strict readers (duplicate JSON keys, the rig map's limit), and the
// order of a task's checks (docs/RELIABILITY.md, "Outputs and clients").
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "motionfield.h"
#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

namespace fs = std::filesystem;

struct SetDeleter {
  void operator()(mf_output_set* s) const { mf_output_set_destroy(s); }
};
using SetPtr = std::unique_ptr<mf_output_set, SetDeleter>;

SetPtr make_set() {
  mf_output_set* s = nullptr;
  EXPECT_EQ(mf_output_set_create(&s), MF_OK) << describe(1);
  return SetPtr(s);
}

::testing::AssertionResult Fails(int got, int status, const std::string& text) {
  const std::string message = mf_last_error_message();
  if (got != status)
    return ::testing::AssertionFailure() << "status " << mf_status_name(got) << ", expected " << mf_status_name(status)
                                         << " (message: " << message << ")";
  if (message.find(text) == std::string::npos)
    return ::testing::AssertionFailure() << "message '" << message << "' lacks '" << text << "'";
  return ::testing::AssertionSuccess();
}

struct ScratchDir {
  std::string path = test::scratch_dir("capi-outputs-" + std::to_string(::getpid()));
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  std::string operator/(const std::string& name) const { return path + "/" + name; }
};

void write_text(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

// The names in `dir` (temporary files left behind show here).
std::set<std::string> listing(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

int write(mf_output_set* s, const std::string& path, const std::string& text) {
  return mf_output_set_write(s, path.c_str(), text.data(), text.size());
}

TEST(CApiOutputs, AnOutputNamedTwiceIsRefusedWhateverItsRole) {
  ScratchDir d;
  fs::create_directories(d / "sub");
  const SetPtr s = make_set();
  ASSERT_EQ(mf_output_set_add_input(s.get(), sample_bvh().c_str(), "input"), MF_OK) << describe(1);
  ASSERT_EQ(mf_output_set_add_output(s.get(), (d / "o.bvh").c_str(), "output"), MF_OK) << describe(1);
  EXPECT_TRUE(Fails(mf_output_set_add_output(s.get(), (d / "o.bvh").c_str(), "report"), MF_ERROR_INVALID_ARGUMENT,
                    "the report " + (d / "o.bvh") + " is also the output " + (d / "o.bvh") +
                        ": refusing to write one file twice (name another output file)"));
  EXPECT_TRUE(Fails(mf_output_set_add_output(s.get(), (d.path + "/./sub/../o.bvh").c_str(), "alternative"),
                    MF_ERROR_INVALID_ARGUMENT, "is also the output"));
  EXPECT_TRUE(Fails(mf_output_set_add_output(s.get(), sample_bvh().c_str(), "report"), MF_ERROR_INVALID_ARGUMENT,
                    "the report " + sample_bvh() + " is the input " + sample_bvh() + ": refusing to overwrite it"));
  // A refused output was not added; a distinct one is accepted, and nothing is written.
  EXPECT_EQ(mf_output_set_add_output(s.get(), (d / "r.json").c_str(), "report"), MF_OK) << describe(1);
  EXPECT_EQ(listing(d.path), std::set<std::string>{"sub"});
}

TEST(CApiOutputs, TheSameFileIsFoundThroughLinks) {
  ScratchDir d;
  write_text(d / "in.bvh", "input");
  fs::create_hard_link(d / "in.bvh", d / "hard.bvh");
  fs::create_symlink("in.bvh", d / "soft.bvh");
  fs::create_symlink("new.bvh", d / "dangling.bvh");
  for (const std::string& out : {d / "hard.bvh", d / "soft.bvh", d.path + "/../" + fs::path(d.path).filename().string() + "/in.bvh"}) {
    const SetPtr s = make_set();
    ASSERT_EQ(mf_output_set_add_input(s.get(), (d / "in.bvh").c_str(), "input"), MF_OK);
    EXPECT_TRUE(Fails(mf_output_set_add_output(s.get(), out.c_str(), "output"), MF_ERROR_INVALID_ARGUMENT,
                      "is the input"))
        << out;
  }
  // A file not there yet, named once directly and once through a dangling link.
  const SetPtr s = make_set();
  ASSERT_EQ(mf_output_set_add_output(s.get(), (d / "new.bvh").c_str(), "output"), MF_OK);
  EXPECT_TRUE(Fails(mf_output_set_add_output(s.get(), (d / "dangling.bvh").c_str(), "report"),
                    MF_ERROR_INVALID_ARGUMENT, "is also the output"));
  EXPECT_EQ(read_text(d / "in.bvh"), "input");
}

TEST(CApiOutputs, DevicesAreWrittenInPlaceAndNeverTheSameFile) {
  const SetPtr s = make_set();
  ASSERT_EQ(mf_output_set_add_output(s.get(), "/dev/null", "output"), MF_OK) << describe(1);
  ASSERT_EQ(mf_output_set_add_output(s.get(), "/dev/null", "report"), MF_OK) << describe(1);
  ASSERT_EQ(write(s.get(), "/dev/null", "{}\n"), MF_OK) << describe(1);
  ASSERT_EQ(mf_output_set_commit(s.get()), MF_OK) << describe(1);
  struct stat st;
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "/dev/null was replaced by a regular file";
}

// A full device fails at the commit with the reason, and the job's other
// outputs are not left behind (nor the file they would have replaced changed).
TEST(CApiOutputs, AFullDeviceFailsTheJobAndLeavesNothingBehind) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  ScratchDir d;
  write_text(d / "old.bvh", "the user's file");
  const SetPtr s = make_set();
  ASSERT_EQ(mf_output_set_add_output(s.get(), (d / "new.bvh").c_str(), "output"), MF_OK);
  ASSERT_EQ(mf_output_set_add_output(s.get(), (d / "old.bvh").c_str(), "alternative"), MF_OK);
  ASSERT_EQ(mf_output_set_add_output(s.get(), "/dev/full", "report"), MF_OK);
  ASSERT_EQ(write(s.get(), d / "new.bvh", "motion"), MF_OK) << describe(1);
  ASSERT_EQ(write(s.get(), d / "old.bvh", "alternative"), MF_OK) << describe(1);
  ASSERT_EQ(write(s.get(), "/dev/full", "{}\n"), MF_OK) << describe(1);
  EXPECT_EQ(mf_output_set_commit(s.get()), MF_ERROR_IO);
  EXPECT_EQ(std::string(mf_last_error_message()), "cannot write /dev/full: No space left on device");
  EXPECT_EQ(listing(d.path), std::set<std::string>{"old.bvh"});
  EXPECT_EQ(read_text(d / "old.bvh"), "the user's file");
  struct stat st;
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

// A set destroyed without its commit (the job failed after staging) leaves nothing.
TEST(CApiOutputs, AnUncommittedSetLeavesNothingBehind) {
  ScratchDir d;
  {
    const SetPtr s = make_set();
    ASSERT_EQ(mf_output_set_add_output(s.get(), (d / "o.bvh").c_str(), "output"), MF_OK);
    ASSERT_EQ(write(s.get(), d / "o.bvh", "motion"), MF_OK);
    EXPECT_EQ(listing(d.path).size(), 1u) << "the staged temporary file";
  }
  EXPECT_EQ(listing(d.path), std::set<std::string>{});
}

// The failure of a write names the reason; a directory the process cannot
// write into (as root, /proc) says so too.
TEST(CApiOutputs, WriteFailuresNameTheReason) {
  ScratchDir d;
  const SetPtr s = make_set();
  EXPECT_TRUE(Fails(mf_output_set_add_output(s.get(), (d / "no/such.json").c_str(), "report"), MF_ERROR_IO,
                    "cannot write " + (d / "no/such.json") + ": directory " + (d / "no") + " does not exist"));
  EXPECT_TRUE(Fails(mf_output_set_add_output(s.get(), d.path.c_str(), "report"), MF_ERROR_IO, "it is a directory"));
  const std::string unwritable = ::geteuid() == 0 ? "/proc/motionfield-report.json" : "/motionfield-report.json";
  ASSERT_EQ(mf_output_set_add_output(s.get(), unwritable.c_str(), "report"), MF_OK) << describe(1);
  const int status = write(s.get(), unwritable, "{}");
  EXPECT_EQ(status, MF_ERROR_IO);
  const std::string message = mf_last_error_message();
  EXPECT_EQ(message.rfind("cannot write " + unwritable + ": ", 0), 0u) << message;
  EXPECT_GT(message.size(), ("cannot write " + unwritable + ": ").size()) << "no reason: " << message;
  EXPECT_TRUE(Fails(write(s.get(), d / "not-added.bvh", "x"), MF_ERROR_INVALID_ARGUMENT, "is not an output"));
}

// Temporary files have unique names: a user's r.json.tmp is never touched.
TEST(CApiOutputs, TemporaryNamesNeverTouchTheUsersFiles) {
  ScratchDir d;
  write_text(d / "r.json.tmp", "mine");
  write_text(d / "o.bvh.tmp", "mine too");
  const MotionPtr m = [] {
    mf_motion* out = nullptr;
    EXPECT_EQ(mf_motion_load_bvh(sample_bvh().c_str(), nullptr, &out), MF_OK);
    return MotionPtr(out);
  }();
  ASSERT_EQ(mf_motion_save_bvh(m.get(), (d / "o.bvh").c_str(), nullptr), MF_OK) << describe(1);
  const SetPtr s = make_set();
  ASSERT_EQ(mf_output_set_add_output(s.get(), (d / "r.json").c_str(), "report"), MF_OK);
  ASSERT_EQ(write(s.get(), d / "r.json", "{}\n"), MF_OK);
  ASSERT_EQ(mf_output_set_commit(s.get()), MF_OK) << describe(1);
  EXPECT_EQ(read_text(d / "r.json.tmp"), "mine");
  EXPECT_EQ(read_text(d / "o.bvh.tmp"), "mine too");
  EXPECT_EQ(read_text(d / "r.json"), "{}\n");
  EXPECT_EQ(listing(d.path), (std::set<std::string>{"o.bvh", "o.bvh.tmp", "r.json", "r.json.tmp"}));
}

// An output through a symbolic link replaces the file it points to and keeps the link.
TEST(CApiOutputs, ALinkedOutputKeepsItsLink) {
  ScratchDir d;
  write_text(d / "target.json", "old");
  fs::create_symlink("target.json", d / "link.json");
  const SetPtr s = make_set();
  ASSERT_EQ(mf_output_set_add_output(s.get(), (d / "link.json").c_str(), "report"), MF_OK);
  ASSERT_EQ(write(s.get(), d / "link.json", "new"), MF_OK);
  ASSERT_EQ(mf_output_set_commit(s.get()), MF_OK) << describe(1);
  EXPECT_TRUE(fs::is_symlink(d / "link.json"));
  EXPECT_EQ(read_text(d / "target.json"), "new");
}

// The name of an open descriptor (/dev/fd/N, as /dev/stdout redirected to a
// file) is written in place: the file it leads to keeps its inode and holds
// exactly the new bytes; /dev itself is never written into.
TEST(CApiOutputs, ADescriptorsNameIsWrittenInPlace) {
  ScratchDir d;
  write_text(d / "redirected.txt", "an older and longer content");
  const int fd = ::open((d / "redirected.txt").c_str(), O_WRONLY);
  ASSERT_GE(fd, 0);
  struct stat before, after;
  ASSERT_EQ(::stat((d / "redirected.txt").c_str(), &before), 0);
  const SetPtr s = make_set();
  const std::string name = "/dev/fd/" + std::to_string(fd);
  ASSERT_EQ(mf_output_set_add_output(s.get(), name.c_str(), "output"), MF_OK) << describe(1);
  ASSERT_EQ(write(s.get(), name, "new"), MF_OK) << describe(1);
  ASSERT_EQ(mf_output_set_commit(s.get()), MF_OK) << describe(1);
  ::close(fd);
  ASSERT_EQ(::stat((d / "redirected.txt").c_str(), &after), 0);
  EXPECT_EQ(before.st_ino, after.st_ino);
  EXPECT_EQ(read_text(d / "redirected.txt"), "new");
  EXPECT_TRUE(fs::is_symlink("/dev/fd") || fs::is_directory("/dev/fd"));
}

TEST(CApiOutputs, MergingJobsIsAllOrNothing) {
  ScratchDir d;
  write_text(d / "in.bvh", "input");
  const SetPtr batch = make_set();
  const SetPtr one = make_set();
  ASSERT_EQ(mf_output_set_add_input(one.get(), (d / "in.bvh").c_str(), "input"), MF_OK);
  ASSERT_EQ(mf_output_set_add_output(one.get(), (d / "a.bvh").c_str(), "output"), MF_OK);
  ASSERT_EQ(mf_output_set_merge(batch.get(), one.get(), "line 1"), MF_OK) << describe(1);
  // Line 2 writes b.bvh (new) and a.bvh (line 1's): refused, and b.bvh not claimed.
  const SetPtr two = make_set();
  ASSERT_EQ(mf_output_set_add_output(two.get(), (d / "b.bvh").c_str(), "output"), MF_OK);
  ASSERT_EQ(mf_output_set_add_output(two.get(), (d.path + "/./a.bvh").c_str(), "report"), MF_OK);
  EXPECT_TRUE(Fails(mf_output_set_merge(batch.get(), two.get(), "line 2"), MF_ERROR_INVALID_ARGUMENT,
                    "line 1 already writes " + d.path + "/./a.bvh: refusing to overwrite another job's output"));
  const SetPtr three = make_set();
  ASSERT_EQ(mf_output_set_add_output(three.get(), (d / "b.bvh").c_str(), "output"), MF_OK);
  EXPECT_EQ(mf_output_set_merge(batch.get(), three.get(), "line 3"), MF_OK) << describe(1);
  // Line 4 writes line 1's input; line 5 reads line 3's output.
  const SetPtr four = make_set();
  ASSERT_EQ(mf_output_set_add_output(four.get(), (d / "in.bvh").c_str(), "output"), MF_OK);
  EXPECT_TRUE(Fails(mf_output_set_merge(batch.get(), four.get(), "line 4"), MF_ERROR_INVALID_ARGUMENT,
                    "line 1 reads " + (d / "in.bvh")));
  const SetPtr five = make_set();
  ASSERT_EQ(mf_output_set_add_input(five.get(), (d / "b.bvh").c_str(), "input"), MF_OK);
  EXPECT_TRUE(Fails(mf_output_set_merge(batch.get(), five.get(), "line 5"), MF_ERROR_INVALID_ARGUMENT,
                    "line 3 writes " + (d / "b.bvh") + ", which this job reads"));
  EXPECT_TRUE(Fails(mf_output_set_merge(batch.get(), batch.get(), "line 6"), MF_ERROR_INVALID_ARGUMENT, "itself"));
}

// Property: jobs with random, overlapping output and input names (the same
// file by other names, links, hard links) are either refused, with nothing
// written and the inputs unchanged, or every output holds exactly what was
// written to it.
TEST(CApiOutputs, RandomJobsEitherAreRefusedOrWriteEveryOutput) {
  ScratchDir d;
  write_text(d / "in.bvh", "input");
  fs::create_hard_link(d / "in.bvh", d / "in-hard.bvh");
  fs::create_symlink("o.bvh", d / "o-link.bvh");
  fs::create_directories(d / "sub");
  const std::vector<std::string> names = {
      d / "o.bvh",      d.path + "/./o.bvh", d / "sub/../o.bvh", d / "o-link.bvh", d / "o_1.bvh", d / "r.json",
      d / "in.bvh",     d / "in-hard.bvh",   d / "sub/x.bvh",    "/dev/null"};
  std::mt19937 random(52);
  int refused = 0, written = 0;
  for (int trial = 0; trial < 400; ++trial) {
    for (const char* n : {"o.bvh", "o_1.bvh", "r.json", "sub/x.bvh"}) fs::remove(d / n);
    {
      const SetPtr s = make_set();
      ASSERT_EQ(mf_output_set_add_input(s.get(), (d / "in.bvh").c_str(), "input"), MF_OK);
      std::vector<std::string> outputs;
      bool ok = true;
      const int count = 1 + static_cast<int>(random() % 4);
      for (int k = 0; k < count && ok; ++k) {
        const std::string& name = names[random() % names.size()];
        ok = mf_output_set_add_output(s.get(), name.c_str(), k == 0 ? "output" : "report") == MF_OK;
        if (ok) outputs.push_back(name);
      }
      if (!ok) {
        ++refused;
        EXPECT_NE(std::string(mf_last_error_message()).find("refusing"), std::string::npos)
            << mf_last_error_message();
      }
      // Whatever was accepted is staged, each output with its own content;
      // a refused job is then dropped uncommitted.
      std::map<std::string, std::string> content;
      for (size_t k = 0; k < outputs.size(); ++k) {
        content[outputs[k]] = "output " + std::to_string(k) + " of trial " + std::to_string(trial);
        ASSERT_EQ(write(s.get(), outputs[k], content[outputs[k]]), MF_OK) << describe(1);
      }
      if (ok) {
        ASSERT_EQ(mf_output_set_commit(s.get()), MF_OK) << describe(1);
        ++written;
        for (const auto& [path, text] : content) {
          if (path == "/dev/null") continue;
          EXPECT_EQ(read_text(path), text) << path << " in trial " << trial;
        }
      }
    }
    EXPECT_EQ(read_text(d / "in.bvh"), "input") << "trial " << trial;
    EXPECT_TRUE(fs::is_symlink(d / "o-link.bvh"));
    for (const std::string& n : listing(d.path)) EXPECT_EQ(n.find(".tmp"), std::string::npos) << n;
  }
  EXPECT_GT(refused, 50);
  EXPECT_GT(written, 50);
}

// Property: random batches of jobs over overlapping names. A job is refused
// exactly when its own files clash (an output twice, an output that is its
// input) or, at the merge, when it writes a file an earlier accepted job
// reads or writes, or reads one an earlier job writes; devices never clash.
TEST(CApiOutputs, RandomBatchesGiveEachWrittenFileToOneJob) {
  ScratchDir d;
  write_text(d / "a.bvh", "a");
  write_text(d / "b.bvh", "b");
  fs::create_hard_link(d / "a.bvh", d / "h.bvh");
  fs::create_symlink("c.bvh", d / "l.bvh");
  fs::create_directories(d / "sub");
  // Each name and the file it is ("" for a device).
  const std::vector<std::pair<std::string, std::string>> names = {
      {d / "a.bvh", "a"}, {d / "h.bvh", "a"},      {d / "b.bvh", "b"},   {d / "sub/../b.bvh", "b"},
      {d / "c.bvh", "c"}, {d.path + "/./c.bvh", "c"}, {d / "l.bvh", "c"}, {d / "e.json", "e"},
      {"/dev/null", ""}};
  std::mt19937 random(5252);
  int merged = 0, refused_by_job = 0, refused_by_batch = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const SetPtr batch = make_set();
    std::set<std::string> written, read;
    for (int line = 1; line <= 5; ++line) {
      const SetPtr job = make_set();
      const auto& [in, in_file] = names[random() % names.size()];
      ASSERT_EQ(mf_output_set_add_input(job.get(), in.c_str(), "input"), MF_OK);
      std::set<std::string> outs;
      bool job_ok = true, clash = false;
      const int count = 1 + static_cast<int>(random() % 3);
      for (int k = 0; k < count && job_ok; ++k) {
        const auto& [out, file] = names[random() % names.size()];
        const bool expected_ok = file.empty() || (file != in_file && outs.count(file) == 0);
        job_ok = mf_output_set_add_output(job.get(), out.c_str(), "output") == MF_OK;
        ASSERT_EQ(job_ok, expected_ok) << out << ": " << mf_last_error_message();
        if (!file.empty()) outs.insert(file);
      }
      if (!job_ok) {
        ++refused_by_job;
        continue;
      }
      for (const std::string& f : outs) clash = clash || written.count(f) || read.count(f);
      clash = clash || (!in_file.empty() && written.count(in_file));
      const std::string label = "line " + std::to_string(line);
      const int status = mf_output_set_merge(batch.get(), job.get(), label.c_str());
      ASSERT_EQ(status, clash ? MF_ERROR_INVALID_ARGUMENT : MF_OK) << "trial " << trial << " " << label << ": "
                                                                   << mf_last_error_message();
      if (clash) {
        ++refused_by_batch;
        continue;
      }
      ++merged;
      written.insert(outs.begin(), outs.end());
      if (!in_file.empty()) read.insert(in_file);
    }
  }
  EXPECT_GT(merged, 100);
  EXPECT_GT(refused_by_job, 50);
  EXPECT_GT(refused_by_batch, 100);
}

// Strict readers: a duplicate key is refused with the key and the place.
TEST(CApiOutputs, ConstraintsWithADuplicateKeyAreRefused) {
  mf_constraints* c = nullptr;
  const std::string top = R"({"keys": [{"frame": 0, "joints": ["Hips"]}], "keys": []})";
  EXPECT_TRUE(Fails(mf_constraints_parse_json(top.data(), top.size(), &c), MF_ERROR_INVALID_ARGUMENT,
                    "duplicate key \"keys\" in the top-level object"));
  const std::string nested = R"({"targets": [{"frame": 1, "joint": "Hand_R", "position": [0, 1, 0]},
      {"frame": 2, "joint": "Hand_R", "frame": 3, "position": [0, 1, 0]}]})";
  EXPECT_TRUE(Fails(mf_constraints_parse_json(nested.data(), nested.size(), &c), MF_ERROR_INVALID_ARGUMENT,
                    "duplicate key \"frame\" in targets[1]"));
  EXPECT_EQ(c, nullptr);
  ScratchDir d;
  write_text(d / "c.json", top);
  EXPECT_TRUE(Fails(mf_constraints_load_json((d / "c.json").c_str(), &c), MF_ERROR_INVALID_ARGUMENT,
                    d / "c.json" + ": duplicate key \"keys\""));
  EXPECT_EQ(c, nullptr);
}

TEST(CApiOutputs, RigMapFilesAreReadWithTheirLimit) {
  ScratchDir d;
  write_text(d / "map.json", R"({"Hips": "Hips"})");
  char text[64];
  size_t needed = 0;
  ASSERT_EQ(mf_rig_map_read_file((d / "map.json").c_str(), text, sizeof text, &needed), MF_OK) << describe(1);
  EXPECT_EQ(std::string(text), R"({"Hips": "Hips"})");
  write_text(d / "big.json", "{" + std::string(2 << 20, ' ') + "}");
  EXPECT_TRUE(Fails(mf_rig_map_read_file((d / "big.json").c_str(), nullptr, 0, &needed), MF_ERROR_IO,
                    "larger than the limit of 1 MiB for a rig map file"));
  EXPECT_TRUE(Fails(mf_rig_map_read_file("/dev/zero", nullptr, 0, &needed), MF_ERROR_IO, "it is a device"));
}

// A task's checks in the order a user thinks: the method against the task
// before the rig, the rig before the frames.
TEST(CApiOutputs, TheMethodIsCheckedBeforeTheRigAndTheRigBeforeTheFrames) {
  const ModelPtr model = load_tiny_model();
  mf_motion* sample = nullptr;
  ASSERT_EQ(mf_motion_load_bvh(sample_bvh().c_str(), nullptr, &sample), MF_OK);
  const MotionPtr input(sample);  // 22 joints: not the tiny model's rig, which has no anatomy
  mf_task_options options;
  mf_task_options_init(&options);
  mf_motion* out = nullptr;
  const int32_t keys[] = {0, 999};
  options.method = "prior";
  EXPECT_TRUE(Fails(mf_inbetween(model.get(), input.get(), keys, 2, &options, &out), MF_ERROR_INVALID_ARGUMENT,
                    "method 'prior' does not do in-betweening"));
  EXPECT_TRUE(Fails(mf_fill(model.get(), input.get(), 10, 20, &options, &out), MF_ERROR_INVALID_ARGUMENT,
                    "method 'prior' does not do in-betweening"));
  options.method = "nemf";
  const int status = mf_inbetween(model.get(), input.get(), keys, 2, &options, &out);
  EXPECT_EQ(status, MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(std::string(mf_last_error_message()).find("keyframe"), std::string::npos)
      << "the frames were checked before the rig: " << mf_last_error_message();
  EXPECT_EQ(out, nullptr);
}

}  // namespace
}  // namespace mf::capi_test
