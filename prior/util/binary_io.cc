#include "prior/util/binary_io.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <utility>

namespace mf {

namespace {

std::string mib(size_t bytes) { return std::to_string(bytes >> 20) + " MiB"; }

std::string too_large(const std::string& path, const std::string& what, size_t max_bytes) {
  return "cannot read " + what + " " + path + ": larger than the limit of " + mib(max_bytes) + " for a " + what;
}

// Opens `path` for reading after the checks of read_file_limited (a
// directory, a device or a regular file over `max_bytes` is refused);
// `st` receives the open file's status.
int open_checked(const std::string& path, const std::string& what, size_t max_bytes, struct stat* st) {
  if (::stat(path.c_str(), st) != 0) throw FileError("cannot open " + what + " " + path + ": " + std::strerror(errno));
  const std::string cannot = "cannot read " + what + " " + path + ": ";
  if (S_ISDIR(st->st_mode)) throw FileError(cannot + "it is a directory");
  if (S_ISCHR(st->st_mode) || S_ISBLK(st->st_mode)) throw FileError(cannot + "it is a device, not a file");
  if (S_ISREG(st->st_mode) && static_cast<uint64_t>(st->st_size) > max_bytes) throw FileError(too_large(path, what, max_bytes));
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw FileError("cannot open " + what + " " + path + ": " + std::strerror(errno));
  return fd;
}

// Reads `fd` (opened by open_checked, with status `st`) to its end and closes it.
std::string read_open_file(int fd, const struct stat& st, const std::string& path, const std::string& what,
                           size_t max_bytes) {
  std::string text;
  if (S_ISREG(st.st_mode)) text.reserve(static_cast<size_t>(st.st_size));
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error = errno;
      ::close(fd);
      throw FileError("cannot read " + what + " " + path + ": " + std::strerror(error));
    }
    if (n == 0) break;
    if (text.size() + static_cast<size_t>(n) > max_bytes) {
      ::close(fd);
      throw FileError(too_large(path, what, max_bytes));
    }
    text.append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  return text;
}

}  // namespace

std::string read_file_limited(const std::string& path, const std::string& what, size_t max_bytes) {
  struct stat st;
  const int fd = open_checked(path, what, max_bytes, &st);
  return read_open_file(fd, st, path, what, max_bytes);
}

FileBytes::~FileBytes() {
  if (map_) ::munmap(map_, map_size_);
}

FileBytes::FileBytes(FileBytes&& other) noexcept
    : map_(std::exchange(other.map_, nullptr)), map_size_(std::exchange(other.map_size_, 0)), text_(std::move(other.text_)) {}

FileBytes& FileBytes::operator=(FileBytes&& other) noexcept {
  if (this != &other) {
    if (map_) ::munmap(map_, map_size_);
    map_ = std::exchange(other.map_, nullptr);
    map_size_ = std::exchange(other.map_size_, 0);
    text_ = std::move(other.text_);
  }
  return *this;
}

const uint8_t* FileBytes::data() const {
  return map_ ? static_cast<const uint8_t*>(map_) : reinterpret_cast<const uint8_t*>(text_.data());
}

size_t FileBytes::size() const { return map_ ? map_size_ : text_.size(); }

void FileBytes::release(const uint8_t* begin, size_t n) const {
  if (!map_ || n == 0) return;
  const uintptr_t base = reinterpret_cast<uintptr_t>(map_);  // page-aligned
  const uintptr_t page = static_cast<uintptr_t>(::sysconf(_SC_PAGESIZE));
  const uintptr_t lo = reinterpret_cast<uintptr_t>(begin);
  if (lo < base || n > map_size_ || lo - base > map_size_ - n) return;
  const uintptr_t first = (lo + page - 1) / page * page, end = (lo + n) / page * page;
  if (end > first) ::madvise(reinterpret_cast<void*>(first), end - first, MADV_DONTNEED);
}

FileBytes read_file_bytes(const std::string& path) {
  const std::string what = "model file";
  FileBytes out;
  struct stat st;
  const int fd = open_checked(path, what, kMaxModelFileBytes, &st);
  // The open file's own status: the path may have been replaced since stat().
  if (::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && st.st_size > 0 &&
      static_cast<uint64_t>(st.st_size) <= kMaxModelFileBytes) {
    const size_t size = static_cast<size_t>(st.st_size);
    // MAP_POPULATE maps the whole file up front (one call instead of a fault per page).
    void* map = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    if (map != MAP_FAILED) {
      ::close(fd);
      out.map_ = map;
      out.map_size_ = size;
      return out;
    }
  }
  // Not mapped (a pipe, a FIFO): read from the same descriptor, since a FIFO's
  // writer must never see its reader close before the end.
  out.text_ = read_open_file(fd, st, path, what, kMaxModelFileBytes);
  return out;
}

}  // namespace mf
