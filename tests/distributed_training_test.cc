// Data-parallel training (training/data_parallel.h) with real processes of
// motionfield-train on loopback: 2 processes with batch 4 end with the
// weights of 1 process with batch 8 (also across a resume); a dead or missing
// rank stops the other with a clear error within the timeout; a resume with
// another world size is refused.
#include <arpa/inet.h>
#include <fcntl.h>
#include <ATen/ATen.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "prior/inbetween/inbetweener.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "prior/motion/motion_bvh.h"
#include "tests/test_util.h"
#include "training/data_parallel.h"

extern char** environ;

namespace mf {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const std::string kTrainer = std::string(MF_BINARY_DIR) + "/training/motionfield-train";

// A process of motionfield-train with stdout and stderr in `log`.
struct Process {
  pid_t pid = -1;
  std::string log;
};

Process start(const std::vector<std::string>& args, const std::string& log) {
  std::vector<std::string> all = {kTrainer};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  Process p;
  p.log = log;
  const int rc = posix_spawn(&p.pid, kTrainer.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("cannot start " + kTrainer);
  return p;
}

// The exit code, or -1 when the process is still running after `seconds` (then killed).
int wait_for(const Process& p, double seconds) {
  const auto t0 = Clock::now();
  int status = 0;
  while (waitpid(p.pid, &status, WNOHANG) == 0) {
    if (std::chrono::duration<double>(Clock::now() - t0).count() > seconds) {
      kill(p.pid, SIGKILL);
      waitpid(p.pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// A TCP port on loopback that was free a moment ago.
int free_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t n = sizeof(a);
  if (bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) != 0 ||
      getsockname(fd, reinterpret_cast<sockaddr*>(&a), &n) != 0) {
    close(fd);
    throw std::runtime_error("no free port");
  }
  close(fd);
  return ntohs(a.sin_port);
}

// Clips of 60..95 frames: every 32-frame window is full length, so the
// losses of the two shards weigh exactly as in the combined batch.
std::string make_data(const std::string& name) {
  const std::string dir = test::scratch_dir(name);
  const Skeleton s = test::small_skeleton();
  for (int i = 0; i < 12; ++i) {
    write_motion(dir + "/clip" + std::to_string(i) + ".bvh", test::random_motion(s, 60 + 3 * i, 30.0, 700 + i),
                 default_bvh_layout(s));
  }
  return dir;
}

// The tiny prior of test::tiny_nemf_config(); a budget so large that the
// time-based learning-rate schedule and KL warm-up stay at their start.
std::vector<std::string> prior_args(const std::string& data, const std::string& out, int batch, int steps) {
  return {"prior", "--data", data, "--cache-dir", data + "/cache", "--out", out, "--width", "32", "--layers", "3",
          "--zl", "8", "--zg", "4", "--zg-layers", "2", "--encoder-channels", "4", "--gmp-width", "8",
          "--gmp-blocks", "1", "--window", "32", "--stride", "16", "--batch", std::to_string(batch), "--max-steps",
          std::to_string(steps), "--max-minutes", "1000000", "--threads", "1", "--seed", "5", "--quiet"};
}

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

// Runs ranks 0 and 1 (rank 1 writes into its own folder, as on another host)
// and expects both to succeed.
void run_two(const std::vector<std::string>& args0, const std::vector<std::string>& args1, const std::string& dir) {
  const std::string master = "127.0.0.1:" + std::to_string(free_port());
  const std::vector<std::string> group = {"--world-size", "2", "--master", master, "--dist-timeout", "60"};
  Process r0 = start(with(with(args0, group), {"--rank", "0"}), dir + "/rank0.log");
  Process r1 = start(with(with(args1, group), {"--rank", "1"}), dir + "/rank1.log");
  const int c1 = wait_for(r1, 110), c0 = wait_for(r0, 110);
  EXPECT_EQ(c0, 0) << read_text(r0.log);
  EXPECT_EQ(c1, 0) << read_text(r1.log);
}

// max |a - b| / max |a| over two lists of parameters.
double relative_difference(const std::vector<at::Tensor>& pa, const std::vector<at::Tensor>& pb) {
  EXPECT_EQ(pa.size(), pb.size());
  double diff = 0, scale = 0;
  for (size_t i = 0; i < pa.size() && i < pb.size(); ++i) {
    diff = std::max(diff, (pa[i] - pb[i]).abs().max().item<double>());
    scale = std::max(scale, pa[i].abs().max().item<double>());
  }
  return diff / scale;
}

// The same over the parameters of two prior checkpoints.
double relative_difference(const std::string& a_path, const std::string& b_path) {
  return relative_difference(load_nemf(a_path).parameters(), load_nemf(b_path).parameters());
}

TEST(distributed, ShardsSplitTheGlobalBatchInRankOrder) {
  DistributedOptions o;
  EXPECT_EQ(o.validate(), "");
  training::DataParallel single(o);  // world size 1: no group, identity collectives
  EXPECT_FALSE(single.distributed());
  EXPECT_EQ(single.shard(8, 16), std::make_pair(size_t{8}, size_t{16}));
  EXPECT_EQ(single.sum({1.5, 2.0}), (std::vector<double>{1.5, 2.0}));
  o.world_size = 3;
  o.rank = 3;
  EXPECT_NE(o.validate().find("--rank"), std::string::npos);
  EXPECT_THROW(training::DataParallel bad(o), InputError);
  o.set_master("10.0.0.7:1234");
  EXPECT_EQ(o.master_addr, "10.0.0.7");
  EXPECT_EQ(o.master_port, 1234);
  EXPECT_THROW(o.set_master("10.0.0.7"), InputError);
  EXPECT_THROW(o.set_master("host:port"), InputError);
}

// The acceptance test of data-parallel training: 2 processes with batch 4
// end with the weights of 1 process with batch 8, within 1e-5 of the largest
// weight (float32 sums in another order), after 4 steps and after a resume to 7.
TEST(distributed, TwoProcessesEndWithTheWeightsOfOneProcessOnTheCombinedBatch) {
  const std::string data = make_data("distributed_same_weights");
  const std::string one = data + "/one", two = data + "/two", two_r1 = data + "/two-rank1";
  Process ref = start(prior_args(data, one, 8, 4), data + "/one.log");
  ASSERT_EQ(wait_for(ref, 110), 0) << read_text(data + "/one.log");
  run_two(prior_args(data, two, 4, 4), prior_args(data, two_r1, 4, 4), data);
  ASSERT_TRUE(fs::exists(two + "/last.mfm"));
  EXPECT_FALSE(fs::exists(two_r1 + "/last.mfm")) << "rank 1 must not write checkpoints";
  EXPECT_FALSE(fs::exists(two_r1 + "/log.csv")) << "rank 1 must not write logs";
  const double after4 = relative_difference(one + "/last.mfm", two + "/last.mfm");
  EXPECT_LT(after4, 1e-5);
  fs::copy_file(one + "/last.mfm", data + "/one-step4.mfm");

  // Resume both to step 7; rank 1 has no checkpoint of its own and gets rank 0's.
  Process ref2 = start(with(prior_args(data, one, 8, 7), {"--resume"}), data + "/one-resume.log");
  ASSERT_EQ(wait_for(ref2, 110), 0) << read_text(data + "/one-resume.log");
  run_two(with(prior_args(data, two, 4, 7), {"--resume"}), with(prior_args(data, two_r1, 4, 7), {"--resume"}), data);
  const std::string log = read_text(two + "/log.csv");
  EXPECT_NE(log.find("\n2,7,"), std::string::npos) << log;  // epoch 2 ended at step 7
  const double after7 = relative_difference(one + "/last.mfm", two + "/last.mfm");
  EXPECT_LT(after7, 1e-5);
  // The weights did move between the checkpoints (the comparisons are not vacuous).
  const double moved = relative_difference(data + "/one-step4.mfm", one + "/last.mfm");
  EXPECT_GT(moved, 1e-4);
  std::printf("relative weight difference after 7 steps: %.2e (the weights moved by %.2e from step 4)\n", after7,
              moved);
  std::printf("relative weight difference after 4 steps: %.2e\n", after4);
}

// The in-betweeners' trainer shares the code: a tiny two-stage transformer,
// 2 processes with batch 4 against 1 with batch 8 (step-based schedule).
// --min-length 32 = the window: every sample is 32 frames long, so the shards
// are padded like the combined batch (with windows of mixed lengths the
// padding changes the float summation order and Adam amplifies it: 1.3e-5
// measured with --min-length 12).
TEST(distributed, TwoProcessesTrainTheInbetweenerAsOneOnTheCombinedBatch) {
  const std::string data = make_data("distributed_inbetweener");
  auto args = [&](const std::string& out, int batch) {
    return std::vector<std::string>{"twostage", "--data", data, "--cache-dir", data + "/cache", "--out", out,
                                    "--hp", "width=16", "--hp", "layers=1", "--hp", "heads=2", "--hp", "ffn=32",
                                    "--hp", "window=32", "--min-length", "32", "--batch", std::to_string(batch), "--max-steps", "4",
                                    "--epoch-steps", "2", "--validation-windows", "8", "--max-minutes", "1000000",
                                    "--threads", "1", "--seed", "3", "--quiet"};
  };
  Process ref = start(args(data + "/one", 8), data + "/one.log");
  ASSERT_EQ(wait_for(ref, 110), 0) << read_text(data + "/one.log");
  run_two(args(data + "/two", 4), args(data + "/two-rank1", 4), data);
  const auto one = load_inbetweener(data + "/one/last.mfm"), two = load_inbetweener(data + "/two/last.mfm");
  // The attention key biases and the relative-position score biases shift
  // every score of a softmax row alike: their true gradient is 0, the computed
  // one float rounding noise that Adam normalises into steps of about the
  // learning rate (measured: 1.1e-5 there, at most 2e-8 anywhere else; 1
  // process at 2 threads instead of 1 differs by 1.7e-6 for the same reason).
  std::vector<at::Tensor> pa, pb;
  const auto na = one->named_parameters(), nb = two->named_parameters();
  ASSERT_EQ(na.size(), nb.size());
  for (size_t i = 0; i < na.size(); ++i) {
    const std::string& name = na[i].first;
    const auto ends_with = [&](const std::string& tail) {
      return name.size() >= tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
    };
    if (ends_with("attn.k.bias") || ends_with("attn.relative.fc2.bias")) continue;
    pa.push_back(na[i].second);
    pb.push_back(nb[i].second);
  }
  ASSERT_GT(pa.size(), na.size() / 2);
  const double d = relative_difference(pa, pb);
  std::printf("in-betweener: relative weight difference after 4 steps: %.2e\n", d);
  EXPECT_LT(d, 1e-5);
}

TEST(distributed, ResumeWithAnotherWorldSizeIsRefused) {
  const std::string data = make_data("distributed_resume_world_size");
  run_two(prior_args(data, data + "/two", 2, 2), prior_args(data, data + "/two-rank1", 2, 2), data);
  Process p = start(with(prior_args(data, data + "/two", 4, 4), {"--resume"}), data + "/resume.log");
  EXPECT_EQ(wait_for(p, 110), 2);
  EXPECT_NE(read_text(p.log).find("--world-size 2"), std::string::npos) << read_text(p.log);
}

// Rank 1 is killed while both train: rank 0 stops with a clear error, well
// within its --dist-timeout of 20 s.
TEST(distributed, AKilledRankStopsTheOtherWithAClearError) {
  const std::string data = make_data("distributed_killed_rank");
  const std::string master = "127.0.0.1:" + std::to_string(free_port());
  const std::vector<std::string> group = {"--world-size", "2", "--master", master, "--dist-timeout", "20"};
  std::vector<std::string> args = prior_args(data, data + "/run", 2, 100000);
  Process r0 = start(with(with(args, group), {"--rank", "0"}), data + "/rank0.log");
  Process r1 = start(with(with(prior_args(data, data + "/run-rank1", 2, 100000), group), {"--rank", "1"}),
                     data + "/rank1.log");
  // Wait until an epoch has ended (both trained), then kill rank 1.
  const auto t0 = Clock::now();
  while (read_text(data + "/run/log.csv").find("\n1,") == std::string::npos &&
         std::chrono::duration<double>(Clock::now() - t0).count() < 60) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_NE(read_text(data + "/run/log.csv").find("\n1,"), std::string::npos) << read_text(r0.log);
  kill(r1.pid, SIGKILL);
  waitpid(r1.pid, nullptr, 0);
  const auto killed = Clock::now();
  const int code = wait_for(r0, 40);
  const double seconds = std::chrono::duration<double>(Clock::now() - killed).count();
  EXPECT_EQ(code, 1) << read_text(r0.log);
  EXPECT_LT(seconds, 25.0);
  const std::string log = read_text(r0.log);
  EXPECT_NE(log.find("rank 0 of 2"), std::string::npos) << log;
  EXPECT_NE(log.find("another process of the group died"), std::string::npos) << log;
  EXPECT_EQ(log.find("internal error"), std::string::npos) << log;
}

// Only rank 0 of 2 is started: it gives up after its --dist-timeout of 3 s.
TEST(distributed, AMissingRankStopsTheOtherAfterTheTimeout) {
  const std::string data = make_data("distributed_missing_rank");
  const std::string master = "127.0.0.1:" + std::to_string(free_port());
  const auto t0 = Clock::now();
  Process r0 = start(with(prior_args(data, data + "/run", 2, 10),
                          {"--world-size", "2", "--rank", "0", "--master", master, "--dist-timeout", "3"}),
                     data + "/rank0.log");
  const int code = wait_for(r0, 60);
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  EXPECT_EQ(code, 1) << read_text(r0.log);
  EXPECT_LT(seconds, 30.0);
  const std::string log = read_text(r0.log);
  EXPECT_NE(log.find("could not form the group of 2 processes"), std::string::npos) << log;
}

}  // namespace
}  // namespace mf
