#include "prior/util/file_writer.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <random>
#include <unordered_map>

namespace mf {

namespace fs = std::filesystem;

namespace {

std::string cannot_write(const std::string& path) { return "cannot write " + path + ": "; }

// Writes all of `data` to `fd`; 0 or the errno of the failure.
int write_all(int fd, const char* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return EIO;
    data += n;
    size -= static_cast<size_t>(n);
  }
  return 0;
}

// Names of open file descriptors (/dev/stdout, /dev/fd/N, /proc/self/fd/N):
// written in place whatever they lead to (a terminal, a pipe, the file the
// shell redirected to), never replaced by a rename.
bool names_a_descriptor(const std::string& path) {
  std::error_code ec;
  const std::string p = fs::absolute(path, ec).lexically_normal().string();
  return p == "/dev/stdout" || p == "/dev/stderr" || p.rfind("/dev/fd/", 0) == 0 ||
         (p.rfind("/proc/", 0) == 0 && p.find("/fd/") != std::string::npos);
}

// The file `path` names once the symbolic links of its last component are
// followed (at most 40, as the kernel does); `path` itself when it is no link.
std::string link_target(const std::string& path) {
  if (names_a_descriptor(path)) return path;
  std::string p = path;
  for (int i = 0; i < 40; ++i) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(p, ec)) || ec) break;
    const fs::path to = fs::read_symlink(p, ec);
    if (ec) break;
    p = to.is_absolute() ? to.string() : (fs::path(p).parent_path() / to).string();
  }
  return p;
}

// A name beside `target` that no file is likely to have: .NAME.<random>.tmp.
std::string temporary_name(const std::string& target) {
  static std::atomic<uint64_t> counter{0};
  thread_local std::mt19937_64 random(std::random_device{}() ^
                                      (static_cast<uint64_t>(::getpid()) << 32) ^
                                      static_cast<uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()));
  char suffix[20];
  std::snprintf(suffix, sizeof suffix, "%016llx", static_cast<unsigned long long>(random() ^ counter++));
  const fs::path p(target);
  return (p.parent_path() / ("." + p.filename().string() + "." + suffix + ".tmp")).string();
}

// What identifies the file `path` names: its device and inode when it
// exists, else its absolute name with links resolved; "" for devices, FIFOs
// and sockets, which are never "the same file" as another output.
std::string identity(const std::string& path) {
  struct stat st;
  if (::stat(path.c_str(), &st) == 0) {
    if (!S_ISREG(st.st_mode) && !S_ISDIR(st.st_mode)) return "";
    return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
  }
  std::error_code ec;
  const fs::path absolute = fs::absolute(link_target(path), ec).lexically_normal();
  const fs::path canonical = fs::weakly_canonical(absolute, ec);
  return "name " + (ec ? absolute : canonical).string();
}

// One output on its way: a temporary file beside its target, or the bytes
// of a device written in place at the end.
struct Staged {
  std::string path;    ///< as the caller named it (messages)
  std::string target;  ///< after following symbolic links
  bool in_place = false;
  std::string temp;    ///< the temporary file, "" once renamed or removed
  std::string bytes;   ///< a device's bytes
};

void discard(Staged& s) noexcept {
  if (!s.temp.empty()) ::unlink(s.temp.c_str());
  s.temp.clear();
}

// Creates a temporary file beside `s.target` (exclusively: never one that
// exists) with the target's permissions when it exists; returns its descriptor.
int create_temporary(Staged& s) {
  struct stat st;
  const bool replaces = ::stat(s.target.c_str(), &st) == 0 && S_ISREG(st.st_mode);
  for (int attempt = 0; attempt < 100; ++attempt) {
    const std::string temp = temporary_name(s.target);
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      s.temp = temp;
      if (replaces) (void)::fchmod(fd, st.st_mode & 07777);
      return fd;
    }
    if (errno != EEXIST) throw FileError(cannot_write(s.path) + std::strerror(errno));
  }
  throw FileError(cannot_write(s.path) + "no unused temporary name beside it");
}

// Stages `size` bytes for `path`: a regular file's are written to its
// temporary file now, a device's kept.
Staged stage(const std::string& path, const void* data, size_t size) {
  Staged s;
  s.path = path;
  s.target = link_target(path);
  const char* bytes = static_cast<const char*>(data);
  struct stat st;
  if (::stat(s.target.c_str(), &st) == 0 && (!S_ISREG(st.st_mode) || names_a_descriptor(path))) {
    if (S_ISDIR(st.st_mode)) throw FileError(cannot_write(path) + "it is a directory");
    s.in_place = true;
    s.bytes.assign(bytes, size);
    return s;
  }
  const int fd = create_temporary(s);
  int error = write_all(fd, bytes, size);
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) {
    discard(s);
    throw FileError(cannot_write(path) + std::strerror(error));
  }
  return s;
}

void write_in_place(const Staged& s) {
  // A regular file behind a descriptor's name is rewritten from its start, as `cp x /dev/stdout` does.
  struct stat st;
  const bool regular = ::stat(s.target.c_str(), &st) == 0 && S_ISREG(st.st_mode);
  const int fd = ::open(s.target.c_str(), O_WRONLY | O_CLOEXEC | (regular ? O_TRUNC : 0));
  if (fd < 0) throw FileError(cannot_write(s.path) + std::strerror(errno));
  int error = write_all(fd, s.bytes.data(), s.bytes.size());
  if (::close(fd) != 0 && error == 0) error = errno;
  if (error != 0) throw FileError(cannot_write(s.path) + std::strerror(error));
}

void move_into_place(Staged& s) {
  if (::rename(s.temp.c_str(), s.target.c_str()) != 0) {
    const int error = errno;
    discard(s);
    throw FileError(cannot_write(s.path) + std::strerror(error));
  }
  s.temp.clear();
}

void finish(Staged& s) {
  if (s.in_place)
    write_in_place(s);
  else
    move_into_place(s);
}

}  // namespace

void write_file_atomically(const std::string& path, const void* data, size_t size) {
  Staged s = stage(path, data, size);
  try {
    finish(s);
  } catch (...) {
    discard(s);
    throw;
  }
}

struct OutputFiles::Impl {
  struct Entry {
    std::string path, role, key, label;
    bool output = false;
  };
  std::vector<Entry> entries;
  std::unordered_multimap<std::string, size_t> by_key;
  std::vector<Staged> staged;
  bool committed = false;

  // The first entry that is the same file as `key` and conflicts with a new
  // entry (written: `output`), or null.
  const Entry* conflict(const std::string& key, bool output) const {
    if (key.empty()) return nullptr;
    const auto [begin, end] = by_key.equal_range(key);
    for (auto it = begin; it != end; ++it)
      if (output || entries[it->second].output) return &entries[it->second];
    return nullptr;
  }
  void add(Entry e) {
    if (!e.key.empty()) by_key.emplace(e.key, entries.size());
    entries.push_back(std::move(e));
  }
};

OutputFiles::OutputFiles() : impl_(std::make_unique<Impl>()) {}

OutputFiles::~OutputFiles() {
  for (Staged& s : impl_->staged) discard(s);
}

void OutputFiles::add_input(const std::string& path, const std::string& role) {
  if (path.empty()) return;
  Impl::Entry e{path, role, identity(path), "", false};
  if (const Impl::Entry* out = impl_->conflict(e.key, false))
    throw InputError("the " + out->role + " " + out->path + " is the " + role + " " + path +
                     ": refusing to overwrite it (name another output file)");
  impl_->add(std::move(e));
}

void OutputFiles::add_output(const std::string& path, const std::string& role) {
  if (path.empty()) throw InputError("the " + role + " file name is empty");
  struct stat st;
  if (::stat(link_target(path).c_str(), &st) == 0 && S_ISDIR(st.st_mode))
    throw FileError(cannot_write(path) + "it is a directory");
  const fs::path dir = fs::path(path).parent_path();
  std::error_code ec;
  if (!dir.empty() && !fs::is_directory(dir, ec))
    throw FileError(cannot_write(path) + "directory " + dir.string() + " does not exist");
  Impl::Entry e{path, role, identity(path), "", true};
  if (const Impl::Entry* other = impl_->conflict(e.key, true)) {
    if (other->output)
      throw InputError("the " + role + " " + path + " is also the " + other->role + " " + other->path +
                       ": refusing to write one file twice (name another output file)");
    throw InputError("the " + role + " " + path + " is the " + other->role + " " + other->path +
                     ": refusing to overwrite it (name another output file)");
  }
  impl_->add(std::move(e));
}

void OutputFiles::merge(const OutputFiles& job, const std::string& label) {
  for (const Impl::Entry& e : job.impl_->entries) {
    const Impl::Entry* other = impl_->conflict(e.key, e.output);
    if (!other) continue;
    if (other->output && e.output)
      throw InputError(other->label + " already writes " + e.path +
                       ": refusing to overwrite another job's output (give each job its own output files)");
    if (e.output)
      throw InputError(other->label + " reads " + e.path +
                       ": refusing to overwrite another job's input (jobs may run side by side)");
    throw InputError(other->label + " writes " + e.path +
                     ", which this job reads: refusing to read another job's output (jobs may run side by side; "
                     "run them as two batches)");
  }
  for (Impl::Entry e : job.impl_->entries) {
    e.label = label;
    impl_->add(std::move(e));
  }
}

void OutputFiles::write(const std::string& path, const void* data, size_t size) {
  if (impl_->committed) throw InputError("the outputs were written already: " + path + " comes too late");
  bool known = false;
  for (const Impl::Entry& e : impl_->entries) known = known || (e.output && e.path == path);
  if (!known) throw InputError(path + " is not an output of this job (add it first)");
  Staged fresh = stage(path, data, size);
  for (auto it = impl_->staged.begin(); it != impl_->staged.end();) {  // written again: the last bytes count
    if (it->path != path) {
      ++it;
      continue;
    }
    discard(*it);
    it = impl_->staged.erase(it);
  }
  impl_->staged.push_back(std::move(fresh));
}

void OutputFiles::commit() {
  if (impl_->committed) throw InputError("the outputs were written already");
  impl_->committed = true;
  try {
    for (Staged& s : impl_->staged)
      if (s.in_place) write_in_place(s);
    for (Staged& s : impl_->staged)
      if (!s.in_place && !s.temp.empty()) move_into_place(s);
  } catch (...) {
    for (Staged& s : impl_->staged) discard(s);
    throw;
  }
}

}  // namespace mf
