// Bad input and faults at the C API (docs/RELIABILITY.md, "Bad input and
// faults"): writing to devices and full disks, reading devices and huge
// files, messages that quote control bytes or megabytes of input.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "tests/capi/capi_test_util.h"
#include "tests/test_util.h"

namespace mf::capi_test {
namespace {

namespace fs = std::filesystem;

MotionPtr load_sample() {
  mf_motion* m = nullptr;
  EXPECT_EQ(mf_motion_load_bvh(sample_bvh().c_str(), nullptr, &m), MF_OK) << describe(1);
  return MotionPtr(m);
}

std::string printable(const std::string& text) {
  size_t needed = 0;
  EXPECT_EQ(mf_printable_text(text.data(), text.size(), nullptr, 0, &needed), MF_OK);
  std::string out(needed, '\0');
  EXPECT_EQ(mf_printable_text(text.data(), text.size(), out.data(), out.size(), &needed), MF_OK);
  out.resize(needed - 1);
  return out;
}

bool has_control_bytes(const std::string& s) {
  for (unsigned char c : s)
    if (c < 0x20 || c == 0x7F) return true;
  return false;
}

struct ScratchDir {
  std::string path = test::scratch_dir("capi-faults-" + std::to_string(::getpid()));
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

// Item 1: a character device is written in place, never replaced by a file.
TEST(CApiFaults, SavingToDevNullWritesTheDeviceAndKeepsIt) {
  const MotionPtr m = load_sample();
  ASSERT_EQ(mf_motion_save_bvh(m.get(), "/dev/null", nullptr), MF_OK) << describe(1);
  struct stat st;
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode)) << "/dev/null was replaced by a regular file";
}

// Items 1 and 7: a full device fails with the reason.
TEST(CApiFaults, SavingToAFullDeviceFailsWithTheReason) {
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const MotionPtr m = load_sample();
  EXPECT_EQ(mf_motion_save_bvh(m.get(), "/dev/full", nullptr), MF_ERROR_IO);
  EXPECT_EQ(std::string(mf_last_error_message()), "cannot write /dev/full: No space left on device");
  struct stat st;
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

// Item 7: a write failure names the reason, not only the temporary file.
TEST(CApiFaults, WriteFailuresSayWhy) {
  const MotionPtr m = load_sample();
  EXPECT_EQ(mf_motion_save_bvh(m.get(), "/nonexistent-dir/x.bvh", nullptr), MF_ERROR_IO);
  EXPECT_NE(std::string(mf_last_error_message()).find("cannot write /nonexistent-dir/x.bvh: No such file or directory"),
            std::string::npos)
      << mf_last_error_message();
  ScratchDir d;
  const std::string file = d.path + "/x.bvh";
  ASSERT_EQ(mf_motion_save_bvh(m.get(), file.c_str(), nullptr), MF_OK) << describe(1);
  for (const auto& entry : fs::directory_iterator(d.path))
    EXPECT_EQ(entry.path().filename().string(), "x.bvh") << "a temporary file was left behind";
}

// Item 2: devices are refused before reading, whatever they would give.
TEST(CApiFaults, DevicesAreNotReadAsFiles) {
  for (const char* device : {"/dev/zero", "/dev/urandom"}) {
    mf_motion* m = nullptr;
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ(mf_motion_load_bvh(device, nullptr, &m), MF_ERROR_IO) << device;
    EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(1)) << device;
    EXPECT_EQ(std::string(mf_last_error_message()),
              std::string("cannot read BVH file ") + device + ": it is a device, not a file");
    EXPECT_EQ(m, nullptr);
    mf_model* model = nullptr;
    EXPECT_EQ(mf_model_load(device, &model), MF_ERROR_IO);
    EXPECT_NE(std::string(mf_last_error_message()).find("it is a device, not a file"), std::string::npos);
  }
}

// Item 2: a regular file over the limit is refused by its size, before reading.
TEST(CApiFaults, HugeFilesAreRefusedByTheirSize) {
  ScratchDir d;
  const std::string huge = d.path + "/huge.bvh";
  {
    const int fd = ::open(huge.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::ftruncate(fd, off_t{600} << 20), 0);  // sparse: no disk used
    ::close(fd);
  }
  mf_motion* m = nullptr;
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(mf_motion_load_bvh(huge.c_str(), nullptr, &m), MF_ERROR_IO);
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(1));
  EXPECT_EQ(std::string(mf_last_error_message()),
            "cannot read BVH file " + huge + ": larger than the limit of 512 MiB for a BVH file");
}

// Item 2: a FIFO (or pipe) is read up to the limit, then refused: the same
// reader as BVH and model files, shown with a path CSV (64 MiB limit).
TEST(CApiFaults, AnEndlessFifoIsCutAtTheLimit) {
  ScratchDir d;
  const std::string fifo = d.path + "/endless.csv";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd < 0) return;
    const std::string chunk(1 << 16, '0');
    for (int i = 0; i < 70 * 16; ++i)  // 70 MiB, or until the reader closes its end
      if (::write(fd, chunk.data(), chunk.size()) < 0) break;
    ::close(fd);
  });
  std::signal(SIGPIPE, SIG_IGN);
  size_t needed = 0;
  EXPECT_EQ(mf_path_load_csv(fifo.c_str(), nullptr, 0, &needed), MF_ERROR_IO);
  EXPECT_EQ(std::string(mf_last_error_message()),
            "cannot read path file " + fifo + ": larger than the limit of 64 MiB for a path file");
  writer.join();
}

// The local latents of one random motion under `model`.
std::vector<float> local_latents(const mf_model* model) {
  const MotionPtr input = random_capi_motion(40, 30.0, 5);
  mf_encoding* raw = nullptr;
  EXPECT_EQ(mf_encode(model, input.get(), nullptr, &raw), MF_OK) << describe(1);
  const EncodingPtr code(raw);
  size_t n = 0;
  EXPECT_EQ(mf_encoding_get_local_latents(raw, nullptr, 0, &n), MF_OK);
  std::vector<float> z(n);
  EXPECT_EQ(mf_encoding_get_local_latents(raw, z.data(), z.size(), &n), MF_OK);
  return z;
}

// Item 2: a model file is mapped, not copied, when it is a regular file
// (FileBytes); through a FIFO it is read instead, and both give the same
// network as the bytes given from memory. SIGPIPE is not ignored here: a
// reader that closed the FIFO before its end (once, between checking and
// reading it) killed the test.
TEST(CApiFaults, AModelLoadsTheSameFromAFileAFifoAndMemory) {
  ScratchDir d;
  const std::string fifo = d.path + "/model.mfm";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::vector<uint8_t>& bytes = tiny_model_bytes();
  std::thread writer([&] {
    const int fd = ::open(fifo.c_str(), O_WRONLY);
    if (fd < 0) return;
    for (size_t done = 0; done < bytes.size();) {
      const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
      if (n <= 0) break;
      done += static_cast<size_t>(n);
    }
    ::close(fd);
  });
  mf_model* piped = nullptr;
  EXPECT_EQ(mf_model_load(fifo.c_str(), &piped), MF_OK) << describe(1);
  writer.join();
  const ModelPtr from_fifo(piped);
  mf_model* in_memory = nullptr;
  ASSERT_EQ(mf_model_load_from_memory(bytes.data(), bytes.size(), &in_memory), MF_OK) << describe(1);
  const ModelPtr from_memory(in_memory);
  const ModelPtr from_file = load_tiny_model();
  ASSERT_TRUE(from_fifo && from_file);
  const std::vector<float> expected = local_latents(from_memory.get());
  ASSERT_FALSE(expected.empty());
  EXPECT_EQ(local_latents(from_file.get()), expected);
  EXPECT_EQ(local_latents(from_fifo.get()), expected);

  // A truncated copy is refused with the reason, mapped or not.
  const std::string cut = d.path + "/cut.mfm";
  std::ofstream(cut, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size() / 2);
  mf_model* broken = nullptr;
  EXPECT_EQ(mf_model_load(cut.c_str(), &broken), MF_ERROR_MODEL);
  EXPECT_NE(std::string(mf_last_error_message()).find("truncated"), std::string::npos) << mf_last_error_message();
  EXPECT_EQ(broken, nullptr);
}

// Item 3: bytes of the input reach messages escaped.
TEST(CApiFaults, ControlBytesOfTheInputAreEscapedInMessages) {
  const std::string bvh = "HIERARCHY\nROOT a\x1b[2J\x1b]0;pwned\x07\n{\n OFFSET 0 0 zero\x1b[31m\n}\n";
  mf_motion* m = nullptr;
  EXPECT_EQ(mf_motion_load_bvh_from_memory(bvh.data(), bvh.size(), nullptr, &m), MF_ERROR_INVALID_ARGUMENT);
  const std::string message = mf_last_error_message();
  EXPECT_FALSE(has_control_bytes(message)) << message;
  EXPECT_NE(message.find("\\x1b"), std::string::npos) << message;

  const std::string path = "/nonexistent/a\x1b[31mred\r\n\x9b" "2J.bvh";
  EXPECT_EQ(mf_motion_load_bvh(path.c_str(), nullptr, &m), MF_ERROR_IO);
  const std::string message2 = mf_last_error_message();
  EXPECT_FALSE(has_control_bytes(message2)) << message2;
  EXPECT_NE(message2.find("a\\x1b[31mred\\r\\n\\x9b2J.bvh"), std::string::npos) << message2;
}

TEST(CApiFaults, PrintableTextEscapesAndIsIdempotent) {
  EXPECT_EQ(printable("plain text, caf\xc3\xa9 \\ ok"), "plain text, caf\xc3\xa9 \\ ok");
  EXPECT_EQ(printable(std::string("a\0b", 3)), "a\\x00b");
  EXPECT_EQ(printable("\t\n\x7f"), "\\t\\n\\x7f");
  EXPECT_EQ(printable("\xc2\x9b" "31m"), "\\u009b31m");        // C1 CSI as UTF-8
  EXPECT_EQ(printable("\xe2\x80\xae" "gpj.bvh"), "\\u202egpj.bvh");  // right-to-left override
  EXPECT_EQ(printable("\xff\xc3"), "\\xff\\xc3");              // invalid UTF-8
  for (const std::string& s : {std::string("a\x1b[0m\xff"), std::string(10000, '\x01'), std::string(9000, 'x')})
    EXPECT_EQ(printable(printable(s)), printable(s));
}

// Item 5: messages are bounded, keeping their start and their end (the reason).
TEST(CApiFaults, LongMessagesAreBounded) {
  const std::string path = "/nonexistent/" + std::string(10 << 20, 'p') + ".bvh";
  mf_motion* m = nullptr;
  EXPECT_EQ(mf_motion_load_bvh(path.c_str(), nullptr, &m), MF_ERROR_IO);
  const std::string message = mf_last_error_message();
  EXPECT_LE(message.size(), static_cast<size_t>(MF_MESSAGE_MAX_BYTES));
  EXPECT_EQ(message.rfind("cannot open BVH file /nonexistent/ppp", 0), 0u) << message.substr(0, 80);
  EXPECT_NE(message.find(" bytes left out) ..."), std::string::npos);
  EXPECT_NE(message.find("pp.bvh: File name too long"), std::string::npos) << message.substr(message.size() - 80);
}

}  // namespace
}  // namespace mf::capi_test
