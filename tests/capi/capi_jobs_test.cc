// The library's batch jobs (mf_job_runner, motionfield.h "batch jobs"): a line
// parsed, checked against the earlier lines and run, with the CLI's messages
// and --json summary; a single command's job; the checks of the C functions.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "motionfield.hpp"
#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

namespace fs = std::filesystem;

struct JobDir {
  std::string path = test::scratch_dir("capi-jobs-" + std::to_string(::getpid()));
  JobDir() { fs::copy_file(sample_bvh(), path + "/walk.bvh"); }
  ~JobDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  std::string operator/(const std::string& name) const { return path + "/" + name; }
};

std::string fill_line(const std::string& in, const std::string& out) {
  return R"({"id": "a", "task": "fill", "in": ")" + in + R"(", "out": ")" + out +
         R"(", "gap": [10, 20], "method": "interp"})";
}

TEST(CApiJobs, ABatchChecksEachLineAgainstTheEarlierOnesAndRunsItWithTheClisMessages) {
  const JobDir dir;
  motionfield::JobRunner runner = motionfield::JobRunner::create({});
  motionfield::Job first = runner.check_line(fill_line(dir / "walk.bvh", dir / "a.bvh"), 1, "jobs.jsonl");
  motionfield::Job again = runner.check_line(fill_line(dir / "walk.bvh", dir / "a.bvh"), 2, "jobs.jsonl");
  motionfield::Job broken = runner.check_line(R"({"task": "fill",})", 3, "jobs.jsonl");
  EXPECT_TRUE(first.runnable());
  EXPECT_FALSE(again.runnable());
  EXPECT_FALSE(broken.runnable());

  const motionfield::JobResult ok = runner.run(first);
  EXPECT_EQ(ok.exit_code, 0) << ok.messages;
  EXPECT_EQ(ok.messages, "");
  EXPECT_EQ(ok.json.rfind(R"({"line":1,"id":"a","task":"fill",)", 0), 0u) << ok.json;
  EXPECT_NE(ok.json.find(R"("status":"ok","method":"interp")"), std::string::npos) << ok.json;
  EXPECT_TRUE(fs::is_regular_file(dir / "a.bvh"));

  const motionfield::JobResult refused = runner.run(again);
  EXPECT_EQ(refused.exit_code, 2);
  EXPECT_EQ(refused.messages.rfind("motionfield: jobs.jsonl line 2 (id a): error: line 1 already writes ", 0), 0u)
      << refused.messages;
  EXPECT_NE(refused.json.find(R"("status":"error","exit_code":2)"), std::string::npos) << refused.json;

  const motionfield::JobResult bad = runner.run(broken);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_EQ(bad.messages.rfind("motionfield: jobs.jsonl line 3: error: invalid JSON: column 17: ", 0), 0u)
      << bad.messages;
  // A job runs once.
  EXPECT_FALSE(first.runnable());
  EXPECT_THROW(runner.run(first), motionfield::Error);
}

TEST(CApiJobs, ALineRunOnItsOwnIsNotCheckedAgainstOthersAndASingleCommandTakesStandardStreamsAndExport) {
  const JobDir dir;
  motionfield::JobRunnerOptions options;
  options.flags = MF_JOB_VERBOSE;
  motionfield::JobRunner runner = motionfield::JobRunner::create(options);
  for (int i = 0; i < 2; ++i) {  // the same output twice: no batch to refuse it
    const motionfield::JobResult r = runner.run_line(fill_line(dir / "walk.bvh", dir / "b.bvh"), 4, "w.jsonl", 0);
    EXPECT_EQ(r.exit_code, 0) << r.messages;
    EXPECT_NE(r.messages.find("motionfield: fill " + dir / "walk.bvh" + " -> " + dir / "b.bvh" +
                              ", model none: 61 -> 61 frames, method interp, 1 threads; read "),
              std::string::npos)
        << r.messages;
  }
  const std::string export_line = R"({"task": "export", "in": ")" + dir / "walk.bvh" + R"(", "out": ")" +
                                  dir / "w.glb" + R"("})";
  const motionfield::JobResult batch = runner.run_line(export_line, 1, "w.jsonl", 0);
  EXPECT_EQ(batch.exit_code, 2);
  EXPECT_NE(batch.messages.find("unknown task \"export\""), std::string::npos) << batch.messages;
  const motionfield::JobResult single = runner.run_line(export_line, 0, "", MF_JOB_SINGLE);
  EXPECT_EQ(single.exit_code, 0) << single.messages;
  EXPECT_TRUE(fs::is_regular_file(dir / "w.glb"));
  EXPECT_EQ(single.json.rfind(R"({"task":"export",)", 0), 0u) << single.json;

  const std::string stdin_line = R"({"task": "fill", "in": "-", "out": "x.bvh", "gap": [1, 5]})";
  const motionfield::JobResult refused = runner.run_line(stdin_line, 7, "w.jsonl", 0);
  EXPECT_EQ(refused.messages, "motionfield: w.jsonl line 7: error: \"-\" (standard input or output) is for single "
                              "commands, not batch jobs\n");
}

TEST(CApiJobs, TheFunctionsCheckTheirArguments) {
  mf_job_runner* runner = nullptr;
  EXPECT_EQ(mf_job_runner_create(nullptr, nullptr), MF_ERROR_INVALID_ARGUMENT);
  mf_job_runner_options options;
  ASSERT_EQ(mf_job_runner_options_init(&options), MF_OK);
  options.units = "furlong";
  EXPECT_EQ(mf_job_runner_create(&options, &runner), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(mf_last_error_message()).find("--units (--length-scale): "), std::string::npos);
  options.units = nullptr;
  options.model = "/nonexistent/model.mfm";
  EXPECT_EQ(mf_job_runner_create(&options, &runner), MF_ERROR_IO);
  EXPECT_EQ(runner, nullptr);
  ASSERT_EQ(mf_job_runner_create(nullptr, &runner), MF_OK);
  mf_job_result* result = nullptr;
  EXPECT_EQ(mf_job_runner_run_line(runner, nullptr, 3, 1, "j", nullptr, &result), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_job_runner_run_line(runner, "{}", 2, 1, nullptr, nullptr, &result), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_job_runner_check_line(runner, "{}", 2, 1, "j", nullptr), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_job_run(runner, nullptr, nullptr, &result), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_job_result_get_exit_code(nullptr, nullptr), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_job_is_runnable(nullptr), 0);
  mf_job_runner_destroy(runner);
  mf_job_runner_destroy(nullptr);
  mf_job_destroy(nullptr);
  mf_job_result_destroy(nullptr);
}

TEST(CApiJobs, TheEndOfABatchIsItsWorstExitCodeAndTheClisLastLine) {
  const motionfield::BatchSummary failed = motionfield::batch_summary("b.jsonl", {0, 2, 0}, 0);
  EXPECT_EQ(failed.exit_code, 2);
  EXPECT_EQ(failed.line, "motionfield: batch b.jsonl: 3 jobs, 2 ok, 1 failed\n");
  EXPECT_EQ(motionfield::batch_summary("b.jsonl", {2, 1, 0}, MF_JOB_QUIET).exit_code, 1);  // an internal error wins
  const motionfield::BatchSummary ok = motionfield::batch_summary("b.jsonl", {0, 0}, 0);
  EXPECT_EQ(ok.exit_code, 0);
  EXPECT_EQ(ok.line, "");
  EXPECT_EQ(motionfield::batch_summary("b.jsonl", {0, 0}, MF_JOB_VERBOSE).line, "motionfield: batch b.jsonl: 2 jobs, 2 ok, 0 failed\n");
  EXPECT_EQ(motionfield::batch_summary("b.jsonl", {0}, MF_JOB_PROGRESS_SHOWN).line, "motionfield: batch b.jsonl: 1 jobs, 1 ok, 0 failed\n");
  EXPECT_EQ(motionfield::batch_summary("b.jsonl", {0}, MF_JOB_PROGRESS_SHOWN | MF_JOB_QUIET).line, "");
  EXPECT_EQ(motionfield::batch_summary("a\x01b", {1}, 0).line,
            "motionfield: " + motionfield::printable("batch a\x01b: 1 jobs, 0 ok, 1 failed") + "\n");
  int32_t code = -1;
  size_t needed = 0;
  EXPECT_EQ(mf_job_batch_summary("b", nullptr, 0, 0, &code, nullptr, 0, &needed), MF_OK);  // no jobs
  EXPECT_EQ(code, 0);
  EXPECT_EQ(needed, 1u);
  EXPECT_EQ(mf_job_batch_summary(nullptr, nullptr, 0, 0, &code, nullptr, 0, &needed), MF_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(mf_job_batch_summary("b", nullptr, 2, 0, &code, nullptr, 0, &needed), MF_ERROR_INVALID_ARGUMENT);
}

TEST(CApiJobs, AModelSetTakesTheInbetweenersGivenAndSaysWhatDidNotLoad) {
  mf_model* model = nullptr;
  const char* missing[] = {"/nonexistent/twostage.mfm"};
  EXPECT_EQ(mf_model_load_set(tiny_model_path().c_str(), missing, 1, &model), MF_ERROR_IO);
  EXPECT_EQ(model, nullptr);
  ASSERT_EQ(mf_model_load_set(tiny_model_path().c_str(), nullptr, 0, &model), MF_OK) << describe(1);
  ModelPtr owned(model);
  size_t needed = 0;
  ASSERT_EQ(mf_model_get_load_warnings(model, nullptr, 0, &needed), MF_OK);
  EXPECT_EQ(needed, 1u);  // "": nothing next to the tiny model failed to load
}

}  // namespace
}  // namespace mf::capi_test
