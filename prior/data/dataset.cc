#include "prior/data/dataset.h"

#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <sstream>
#include <string_view>
#include <system_error>
#include <thread>

#include "prior/data/tar_archive.h"
#include "prior/motion/errors.h"

#ifndef MF_DEFAULT_TRAIN_ARCHIVE
#define MF_DEFAULT_TRAIN_ARCHIVE ""
#endif
#ifndef MF_DEFAULT_CACHE_DIR
#define MF_DEFAULT_CACHE_DIR ""
#endif

namespace mf {

namespace fs = std::filesystem;

namespace {

// Bump whenever the clips file layout or the meaning of its contents changes
// (including changes to how BVH files are converted): it is part of every key.
constexpr uint32_t kCacheFormatVersion = 1;
constexpr char kClipsMagic[8] = {'M', 'F', 'C', 'L', 'I', 'P', 'S', '\0'};
constexpr uint32_t kByteOrderMark = 0x01020304u;
constexpr size_t kHeaderBytes = 8 + 4 + 4 + 8 + 8;  // magic, version, byte order, payload size, checksum
constexpr double kOffsetTolerance = 1e-3;         // metres
constexpr size_t kMaxStringBytes = 1 << 16;

std::atomic<unsigned> g_temp_counter{0};

std::string hex64(uint64_t v) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

std::string temp_suffix() {
  return ".tmp-" + std::to_string(static_cast<long long>(::getpid())) + "-" + std::to_string(g_temp_counter++);
}

// Removes `<dir>/<prefix>.tmp-<pid>-<n>` entries left by a process that died
// (killed during an extraction or a cache write). An entry is removed only when
// its process no longer exists and it is more than an hour old, so a live
// writer in another PID namespace sharing the folder is not disturbed.
void remove_stale_temps(const fs::path& dir, const std::string& prefix) {
  const std::string start = prefix + ".tmp-";
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string n = it->path().filename().string();
    if (n.compare(0, start.size(), start) != 0) continue;
    const long long pid = std::atoll(n.c_str() + start.size());
    if (pid <= 0 || (::kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH)) continue;
    std::error_code e2;
    const auto age = fs::file_time_type::clock::now() - fs::last_write_time(it->path(), e2);
    if (e2 || age < std::chrono::hours(1)) continue;
    fs::remove_all(it->path(), e2);
  }
}

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// FNV-style checksum over 8-byte words (a byte at a time for the tail). Each
// step is a bijection of the state for a given word, so changing any single
// word of the payload changes the result. Callers feed multiples of 8 bytes
// except in the last call.
struct Checksum {
  uint64_t h = 0xcbf29ce484222325ULL;
  void update(const char* p, size_t n) {
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
      uint64_t w;
      std::memcpy(&w, p + i, 8);
      h = (h ^ w) * 0x100000001b3ULL;
    }
    for (; i < n; ++i) h = (h ^ static_cast<unsigned char>(p[i])) * 0x100000001b3ULL;
  }
};

// ---------------------------------------------------------------- clips file

class PayloadWriter {
 public:
  explicit PayloadWriter(std::ofstream& out) : out_(out) {}
  void bytes(const void* p, size_t n) {
    buf_.append(static_cast<const char*>(p), n);
    if (buf_.size() >= (size_t{1} << 20)) flush(false);
  }
  template <class T>
  void pod(T v) {
    bytes(&v, sizeof v);
  }
  void str(const std::string& s) {
    pod<uint64_t>(s.size());
    bytes(s.data(), s.size());
  }
  void finish() { flush(true); }
  uint64_t size() const { return size_; }
  uint64_t checksum() const { return sum_.h; }

 private:
  void flush(bool all) {
    size_t n = all ? buf_.size() : buf_.size() / 8 * 8;
    sum_.update(buf_.data(), n);
    out_.write(buf_.data(), static_cast<std::streamsize>(n));
    size_ += n;
    buf_.erase(0, n);
  }
  std::ofstream& out_;
  std::string buf_;
  uint64_t size_ = 0;
  Checksum sum_;
};

class PayloadReader {
 public:
  PayloadReader(const char* data, size_t size, const std::string& path) : p_(data), size_(size), path_(path) {}
  [[noreturn]] void fail(const std::string& what) const { throw InputError(path_ + ": " + what); }
  size_t remaining() const { return size_ - pos_; }
  void need(uint64_t n) const {
    if (n > remaining()) fail("truncated or corrupted clips file (needs " + std::to_string(n) + " more bytes at offset " +
                              std::to_string(pos_) + ")");
  }
  void bytes(void* dst, size_t n) {
    need(n);
    std::memcpy(dst, p_ + pos_, n);
    pos_ += n;
  }
  const char* take(size_t n) {
    need(n);
    const char* q = p_ + pos_;
    pos_ += n;
    return q;
  }
  template <class T>
  T pod() {
    T v;
    bytes(&v, sizeof v);
    return v;
  }
  std::string str() {
    uint64_t n = pod<uint64_t>();
    if (n > kMaxStringBytes) fail("corrupted clips file (string of " + std::to_string(n) + " bytes)");
    const char* q = take(static_cast<size_t>(n));
    return std::string(q, static_cast<size_t>(n));
  }

 private:
  const char* p_;
  size_t size_;
  size_t pos_ = 0;
  std::string path_;
};

// One clip's record of the clips file; `buf` is scratch space.
void write_clip(PayloadWriter& w, const Clip& c, const std::string& path, std::vector<double>& buf) {
  const Motion& m = c.motion;
  const int J = m.num_joints(), F = m.num_frames();
  if (m.rotations.size() != static_cast<size_t>(J) * F)
    throw InputError("cannot write clips file " + path + ": clip " + c.name + " has inconsistent sizes");
  w.str(c.name);
  w.pod<double>(m.fps);
  w.pod<uint32_t>(static_cast<uint32_t>(J));
  w.pod<uint32_t>(static_cast<uint32_t>(F));
  for (int j = 0; j < J; ++j) {
    w.str(m.skeleton.names[j]);
    w.pod<int32_t>(m.skeleton.parents[j]);
    const Eigen::Vector3d& o = m.skeleton.offsets[j];
    const double off[3] = {o.x(), o.y(), o.z()};
    w.bytes(off, sizeof off);
  }
  buf.resize(static_cast<size_t>(J) * F * 4);
  for (size_t i = 0; i < m.rotations.size(); ++i) {
    const Eigen::Quaterniond& q = m.rotations[i];
    buf[4 * i] = q.w();
    buf[4 * i + 1] = q.x();
    buf[4 * i + 2] = q.y();
    buf[4 * i + 3] = q.z();
  }
  w.bytes(buf.data(), buf.size() * sizeof(double));
  buf.resize(static_cast<size_t>(F) * 3);
  for (int f = 0; f < F; ++f)
    for (int k = 0; k < 3; ++k) buf[3 * static_cast<size_t>(f) + k] = m.root_positions[f][k];
  w.bytes(buf.data(), buf.size() * sizeof(double));
}

void write_clips_file(const std::string& path, const std::vector<Clip>& clips, const std::vector<std::string>& skipped) {
  const std::string tmp = path + temp_suffix();
  try {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError("cannot write clips file " + path + ": cannot create " + tmp);
    char header[kHeaderBytes] = {};
    out.write(header, sizeof header);  // placeholder, rewritten at the end
    PayloadWriter w(out);
    w.pod<uint64_t>(clips.size());
    std::vector<double> buf;
    for (const Clip& c : clips) write_clip(w, c, path, buf);
    w.pod<uint64_t>(skipped.size());
    for (const std::string& s : skipped) w.str(s.size() > kMaxStringBytes ? s.substr(0, kMaxStringBytes) : s);
    w.finish();

    std::memcpy(header, kClipsMagic, 8);
    const uint32_t version = kCacheFormatVersion, bom = kByteOrderMark;
    const uint64_t size = w.size(), sum = w.checksum();
    std::memcpy(header + 8, &version, 4);
    std::memcpy(header + 12, &bom, 4);
    std::memcpy(header + 16, &size, 8);
    std::memcpy(header + 24, &sum, 8);
    out.seekp(0);
    out.write(header, sizeof header);
    out.close();
    if (!out) throw InputError("cannot write clips file " + path + ": write to " + tmp + " failed");
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) throw InputError("cannot write clips file " + path + ": " + ec.message());
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
}

// The whole file in memory. Not a std::string: zero-filling a few hundred
// megabytes first costs time.
std::unique_ptr<char[]> read_whole_file(const std::string& path, size_t* size) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open clips file");
  in.seekg(0, std::ios::end);
  const std::streamoff file_size = in.tellg();
  in.seekg(0);
  if (file_size < 0) throw InputError(path + ": cannot read clips file");
  *size = static_cast<size_t>(file_size);
  std::unique_ptr<char[]> buffer(new (std::nothrow) char[std::max<size_t>(*size, 1)]);
  if (!buffer) throw InputError(path + ": clips file too large to load (" + std::to_string(*size) + " bytes)");
  in.read(buffer.get(), file_size);
  if (in.gcount() != file_size) throw InputError(path + ": cannot read clips file");
  return buffer;
}

// Checks the header (magic, version, byte order, size, checksum); returns the payload.
std::string_view checked_payload(std::string_view data, const std::string& path) {
  if (data.size() < 8 || std::memcmp(data.data(), kClipsMagic, 8) != 0)
    throw InputError(path + ": not a motionfield clips file");
  if (data.size() < kHeaderBytes) throw InputError(path + ": truncated clips file");
  uint32_t version, bom;
  uint64_t payload_size, sum;
  std::memcpy(&version, data.data() + 8, 4);
  std::memcpy(&bom, data.data() + 12, 4);
  std::memcpy(&payload_size, data.data() + 16, 8);
  std::memcpy(&sum, data.data() + 24, 8);
  if (bom != kByteOrderMark) throw InputError(path + ": clips file written with another byte order");
  if (version != kCacheFormatVersion)
    throw InputError(path + ": clips file format version " + std::to_string(version) + ", expected " +
                     std::to_string(kCacheFormatVersion));
  const uint64_t actual = data.size() - kHeaderBytes;
  if (payload_size != actual)
    throw InputError(path + ": truncated or corrupted clips file (" + std::to_string(actual) + " payload bytes, header says " +
                     std::to_string(payload_size) + ")");
  Checksum check;
  check.update(data.data() + kHeaderBytes, actual);
  if (check.h != sum) throw InputError(path + ": corrupted clips file (checksum mismatch)");
  return data.substr(kHeaderBytes);
}

Clip read_clip(PayloadReader& r, uint64_t index) {
  Clip clip;
  clip.name = r.str();
  Motion& m = clip.motion;
  m.fps = r.pod<double>();
  const uint32_t J = r.pod<uint32_t>(), F = r.pod<uint32_t>();
  if (J < 1 || J > static_cast<uint32_t>(kBvhMaxJoints) || F < 1 || F > static_cast<uint64_t>(kBvhMaxFrames))
    r.fail("corrupted clips file (clip " + std::to_string(index) + ": " + std::to_string(J) + " joints, " +
           std::to_string(F) + " frames)");
  m.skeleton.names.resize(J);
  m.skeleton.parents.resize(J);
  m.skeleton.offsets.resize(J);
  for (uint32_t j = 0; j < J; ++j) {
    m.skeleton.names[j] = r.str();
    m.skeleton.parents[j] = r.pod<int32_t>();
    double off[3];
    r.bytes(off, sizeof off);
    m.skeleton.offsets[j] = Eigen::Vector3d(off[0], off[1], off[2]);
  }
  const uint64_t nq = static_cast<uint64_t>(J) * F;
  r.need(nq * 4 * sizeof(double) + static_cast<uint64_t>(F) * 3 * sizeof(double));
  const char* q = r.take(static_cast<size_t>(nq * 4 * sizeof(double)));
  m.rotations.resize(static_cast<size_t>(nq));
  for (size_t i = 0; i < nq; ++i) {
    double v[4];
    std::memcpy(v, q + 32 * i, 32);
    m.rotations[i] = Eigen::Quaterniond(v[0], v[1], v[2], v[3]);
  }
  const char* p = r.take(static_cast<size_t>(F) * 3 * sizeof(double));
  m.root_positions.resize(F);
  for (uint32_t f = 0; f < F; ++f) {
    double v[3];
    std::memcpy(v, p + 24 * static_cast<size_t>(f), 24);
    m.root_positions[f] = Eigen::Vector3d(v[0], v[1], v[2]);
  }
  try {
    m.skeleton.validate();
    m.validate();
  } catch (const InputError& e) {
    r.fail("corrupted clips file (clip " + clip.name + ": " + e.what() + ")");
  }
  return clip;
}

std::vector<Clip> read_clips_file(const std::string& path, std::vector<std::string>* skipped_out) {
  size_t size = 0;
  const std::unique_ptr<char[]> buffer = read_whole_file(path, &size);
  const std::string_view payload = checked_payload(std::string_view(buffer.get(), size), path);
  PayloadReader r(payload.data(), payload.size(), path);
  const uint64_t num_clips = r.pod<uint64_t>();
  // Every clip takes at least its name length, fps and two counts.
  if (num_clips > r.remaining() / 24) r.fail("corrupted clips file (clip count " + std::to_string(num_clips) + ")");
  std::vector<Clip> clips;
  clips.reserve(static_cast<size_t>(num_clips));
  for (uint64_t c = 0; c < num_clips; ++c) clips.push_back(read_clip(r, c));
  const uint64_t num_skipped = r.pod<uint64_t>();
  if (num_skipped > r.remaining() / 8) r.fail("corrupted clips file (skipped count)");
  std::vector<std::string> skipped(static_cast<size_t>(num_skipped));
  for (auto& s : skipped) s = r.str();
  if (r.remaining() != 0) r.fail("corrupted clips file (trailing bytes)");
  if (skipped_out) *skipped_out = std::move(skipped);
  return clips;
}

// ---------------------------------------------------------------- sources

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

struct FileStamp {
  uint64_t size = 0;
  int64_t mtime_ns = 0;
};

FileStamp stamp(const fs::path& p) {
  struct stat st;
  if (::stat(p.c_str(), &st) != 0) throw InputError("cannot stat " + p.string() + ": " + std::strerror(errno));
  FileStamp s;
  s.size = static_cast<uint64_t>(st.st_size);
  s.mtime_ns = static_cast<int64_t>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec;
  return s;
}

struct SourceFile {
  std::string rel;  // path relative to the root, '/'-separated: the sort key
  fs::path path;
};

std::vector<SourceFile> list_bvh_files(const fs::path& root) {
  std::vector<SourceFile> files;
  std::error_code ec;
  fs::recursive_directory_iterator it(root, fs::directory_options::skip_permission_denied, ec), end;
  if (ec) throw InputError("cannot list " + root.string() + ": " + ec.message());
  for (; it != end; it.increment(ec)) {
    if (ec) throw InputError("cannot list " + root.string() + ": " + ec.message());
    std::error_code ec2;
    if (!it->is_regular_file(ec2)) continue;
    if (lower(it->path().extension().string()) != ".bvh") continue;
    files.push_back({it->path().lexically_relative(root).generic_string(), it->path()});
  }
  if (ec) throw InputError("cannot list " + root.string() + ": " + ec.message());
  std::sort(files.begin(), files.end(), [](const SourceFile& a, const SourceFile& b) { return a.rel < b.rel; });
  return files;
}

uint64_t archive_key(const fs::path& archive) {
  const FileStamp s = stamp(archive);
  std::ostringstream k;
  k << "archive\n" << archive.string() << '\n' << s.size << '\n' << s.mtime_ns << '\n' << kCacheFormatVersion;
  return fnv1a64(k.str());
}

uint64_t folder_key(const fs::path& folder, const std::vector<SourceFile>& files) {
  std::ostringstream k;
  k << "folder\n" << folder.string() << '\n' << kCacheFormatVersion << '\n';
  for (const SourceFile& f : files) {
    const FileStamp s = stamp(f.path);
    k << f.rel << '\n' << s.size << '\n' << s.mtime_ns << '\n';
  }
  return fnv1a64(k.str());
}

// Extracts `archive` into <cache_dir>/extract-<key>/ unless that folder exists.
// libarchive writes into a private temporary folder that is renamed only after
// the whole archive was read, so the final folder always holds a complete
// extraction.
fs::path ensure_extracted(const fs::path& archive, const fs::path& cache_dir, uint64_t key, bool verbose) {
  const fs::path final_dir = cache_dir / ("extract-" + hex64(key));
  std::error_code ec;
  if (fs::is_directory(final_dir, ec)) {
    if (verbose) std::fprintf(stderr, "mf dataset: using extracted %s\n", final_dir.c_str());
    return final_dir;
  }
  remove_stale_temps(cache_dir, "extract-" + hex64(key));
  const fs::path tmp = cache_dir / ("extract-" + hex64(key) + temp_suffix());
  auto cleanup = [&] {
    std::error_code e;
    fs::remove_all(tmp, e);
  };
  fs::create_directories(tmp, ec);
  if (ec) throw InputError("cannot create " + tmp.string() + ": " + ec.message());
  if (verbose) std::fprintf(stderr, "mf dataset: extracting %s\n", archive.c_str());
  const auto t0 = Clock::now();
  try {
    extract_tar_archive(archive.string(), tmp.string());
  } catch (...) {
    cleanup();
    throw;
  }
  fs::rename(tmp, final_dir, ec);
  if (ec) {
    // Another process may have completed the same extraction first.
    std::error_code e2;
    const bool exists = fs::is_directory(final_dir, e2);
    cleanup();
    if (!exists) throw InputError("cannot rename " + tmp.string() + " to " + final_dir.string() + ": " + ec.message());
  }
  if (verbose) std::fprintf(stderr, "mf dataset: extracted in %.1f s\n", seconds_since(t0));
  return final_dir;
}

// ---------------------------------------------------------------- parsing

// Empty if `s` matches the reference skeleton, else the reason.
std::string skeleton_mismatch(const Skeleton& ref, const std::string& ref_name, const Skeleton& s) {
  const std::string as = " (reference clip " + ref_name + ")";
  if (s.num_joints() != ref.num_joints())
    return "skeleton has " + std::to_string(s.num_joints()) + " joints, expected " + std::to_string(ref.num_joints()) + as;
  for (int j = 0; j < ref.num_joints(); ++j) {
    if (s.names[j] != ref.names[j])
      return "joint " + std::to_string(j) + " is '" + s.names[j] + "', expected '" + ref.names[j] + "'" + as;
    if (s.parents[j] != ref.parents[j])
      return "joint '" + s.names[j] + "' has parent " + std::to_string(s.parents[j]) + ", expected " +
             std::to_string(ref.parents[j]) + as;
  }
  for (int j = 1; j < ref.num_joints(); ++j) {
    const double d = (s.offsets[j] - ref.offsets[j]).norm();
    if (!(d <= kOffsetTolerance)) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.2f mm", d * 1000.0);
      return "offset of joint '" + s.names[j] + "' differs by " + buf + " (more than 1 mm)" + as;
    }
  }
  return {};
}

// Runs `worker` on `threads` threads (<= 0: one per hardware thread; at most
// one per item of `items`), the calling thread among them, and waits for all.
template <class Worker>
void run_on_threads(int threads, size_t items, Worker& worker) {
  size_t count = threads > 0 ? static_cast<size_t>(threads) : std::thread::hardware_concurrency();
  count = std::clamp<size_t>(count, 1, std::max<size_t>(items, 1));
  std::vector<std::thread> pool;
  for (size_t t = 1; t < count; ++t) {
    try {
      pool.emplace_back(std::ref(worker));
    } catch (const std::system_error&) {
      break;  // fewer threads; the calling thread still does the work
    }
  }
  worker();
  for (std::thread& t : pool) t.join();
}

void parse_clips(const std::vector<SourceFile>& files, const DatasetOptions& options, std::vector<Clip>* clips,
                 std::vector<std::string>* skipped) {
  const size_t n = files.size();
  std::vector<std::optional<Motion>> motions(n);
  std::vector<std::string> errors(n);
  std::atomic<size_t> next{0}, done{0};
  std::mutex print_mutex;
  const auto t0 = Clock::now();
  auto worker = [&] {
    for (;;) {
      const size_t i = next++;
      if (i >= n) return;
      try {
        motions[i] = read_motion(files[i].path.string(), nullptr, options.units);
      } catch (const std::exception& e) {
        // Messages start with the file's path; the path relative to the source
        // keeps them independent of where an archive was extracted.
        errors[i] = e.what();
        const std::string full = files[i].path.string();
        if (errors[i].compare(0, full.size(), full) == 0) errors[i].replace(0, full.size(), files[i].rel);
        if (errors[i].empty()) errors[i] = "unknown error";
      } catch (...) {
        errors[i] = "unknown error";
      }
      const size_t d = ++done;
      if (options.verbose && (d % 250 == 0 || d == n)) {
        std::lock_guard<std::mutex> lock(print_mutex);
        std::fprintf(stderr, "mf dataset: parsed %zu/%zu clips (%.1f s)\n", d, n, seconds_since(t0));
      }
    }
  };
  run_on_threads(options.threads, n, worker);

  // Sequential from here on: the outcome depends only on the sorted file list.
  const size_t first = clips->size();
  for (size_t i = 0; i < n; ++i) {
    const std::string name = files[i].path.filename().string();
    if (!motions[i]) {
      skipped->push_back(name + ": " + errors[i]);
      continue;
    }
    if (clips->size() > first) {
      const Clip& ref = (*clips)[first];
      const std::string why = skeleton_mismatch(ref.motion.skeleton, ref.name, motions[i]->skeleton);
      if (!why.empty()) {
        skipped->push_back(name + ": " + why);
        motions[i].reset();
        continue;
      }
    }
    clips->push_back(Clip{name, std::move(*motions[i])});
    motions[i].reset();
  }
}

// ---------------------------------------------------------------- loading steps

void check_options(const DatasetOptions& options) {
  if (options.source.empty()) throw InputError("dataset source is empty");
  if (options.validation_percent < 0 || options.validation_percent > 100)
    throw InputError("validation_percent must be within 0..100, got " + std::to_string(options.validation_percent));
  if (!(options.units.length_scale > 0) || !std::isfinite(options.units.length_scale))
    throw InputError("BVH length scale must be positive and finite");
}

// The source and the cache folder of DatasetOptions, made absolute and checked.
struct ResolvedSource {
  fs::path path;
  bool is_folder = false;
  fs::path cache_dir;      // empty: none
  bool use_cache = false;  // read and write the clips file
};

// Also creates the cache folder when it will be written to.
ResolvedSource resolve_source(const DatasetOptions& options) {
  ResolvedSource r;
  std::error_code ec;
  r.path = fs::absolute(options.source, ec).lexically_normal();
  if (ec) throw InputError("bad dataset source " + options.source + ": " + ec.message());
  const fs::file_status st = fs::status(r.path, ec);
  if (!fs::exists(st)) throw InputError("dataset source does not exist: " + options.source);
  r.is_folder = fs::is_directory(st);
  if (!r.is_folder) {
    if (!is_tar_archive_name(r.path.filename().string()) || !fs::is_regular_file(st))
      throw InputError("dataset source is neither a folder nor a .tar, .tar.xz, .txz, .tar.gz or .tgz archive: " +
                       options.source);
    if (options.cache_dir.empty())
      throw InputError("an archive source needs a cache_dir to extract into: " + options.source);
  }
  if (!options.cache_dir.empty()) {
    r.cache_dir = fs::absolute(options.cache_dir, ec).lexically_normal();
    if (ec) throw InputError("bad cache_dir " + options.cache_dir + ": " + ec.message());
  }
  r.use_cache = options.use_cache && !r.cache_dir.empty();
  if (!r.cache_dir.empty() && (r.use_cache || !r.is_folder)) {
    fs::create_directories(r.cache_dir, ec);
    if (ec || !fs::is_directory(r.cache_dir))
      throw InputError("cannot create cache_dir " + r.cache_dir.string() + (ec ? ": " + ec.message() : std::string()));
  }
  return r;
}

// The key of the clips file: the source's key and the length units.
uint64_t clips_key(uint64_t source_key, const BvhUnits& units) {
  char scale[40];
  std::snprintf(scale, sizeof scale, "%.17g", units.length_scale);
  return fnv1a64(hex64(source_key) + "\nlength_scale " + scale);
}

// True when the clips came from `cache_file`; a damaged file is reported and ignored.
bool read_cached_clips(const fs::path& cache_file, std::vector<Clip>* clips, std::vector<std::string>* skipped) {
  std::error_code ec;
  if (!fs::exists(cache_file, ec)) return false;
  try {
    *clips = read_clips_file(cache_file.string(), skipped);
    return true;
  } catch (const InputError& e) {
    std::fprintf(stderr, "mf dataset: ignoring the cache, parsing again: %s\n", e.what());
    clips->clear();
    skipped->clear();
    return false;
  }
}

// Failing to write the cache is only a warning.
void write_cached_clips(const fs::path& cache_file, const std::vector<Clip>& clips,
                        const std::vector<std::string>& skipped, bool verbose) {
  try {
    remove_stale_temps(cache_file.parent_path(), cache_file.filename().string());
    write_clips_file(cache_file.string(), clips, skipped);
    if (verbose) std::fprintf(stderr, "mf dataset: wrote cache %s\n", cache_file.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mf dataset: warning: cache not written: %s\n", e.what());
  }
}

InputError no_usable_clip(const std::string& source, const std::vector<std::string>& skipped) {
  std::string msg = "no usable clip in " + source + " (" + std::to_string(skipped.size()) + " skipped";
  for (size_t i = 0; i < skipped.size() && i < 3; ++i) msg += (i ? "; " : ": ") + skipped[i];
  return InputError(msg + ")");
}

// The reference skeleton (the first clip's) and the split by name.
void split_clips(std::vector<Clip> clips, int validation_percent, Dataset* ds) {
  ds->skeleton = clips.front().motion.skeleton;
  for (Clip& c : clips) {
    if (is_validation_clip(c.name, validation_percent))
      ds->validation.push_back(std::move(c));
    else
      ds->train.push_back(std::move(c));
  }
}

std::string env_or(const char* var, const char* fallback) {
  const char* v = std::getenv(var);
  if (v && *v) return v;
  if (!*fallback) return {};
  return fs::path(fallback).lexically_normal().string();
}

}  // namespace

// ---------------------------------------------------------------- public API

bool is_validation_clip(const std::string& name, int validation_percent) {
  if (validation_percent <= 0) return false;
  return fnv1a64(name) % 100 < static_cast<uint64_t>(validation_percent);
}

std::string default_train_archive() { return env_or("MF_TRAIN_ARCHIVE", MF_DEFAULT_TRAIN_ARCHIVE); }
std::string default_cache_dir() { return env_or("MF_CACHE_DIR", MF_DEFAULT_CACHE_DIR); }
std::string default_foreign_archive() { return env_or("MF_FOREIGN_ARCHIVE", MF_DEFAULT_FOREIGN_ARCHIVE); }

void save_clips(const std::string& path, const std::vector<Clip>& clips) { write_clips_file(path, clips, {}); }

std::vector<Clip> load_clips(const std::string& path) { return read_clips_file(path, nullptr); }

Dataset load_dataset(const DatasetOptions& options) {
  const auto t0 = Clock::now();
  check_options(options);
  const ResolvedSource source = resolve_source(options);
  std::vector<SourceFile> files;
  uint64_t source_key = 0;
  if (source.is_folder) {
    files = list_bvh_files(source.path);
    if (source.use_cache) source_key = folder_key(source.path, files);
  } else {
    source_key = archive_key(source.path);
  }
  const fs::path cache_file = source.cache_dir / ("clips-" + hex64(clips_key(source_key, options.units)) + ".bin");

  Dataset ds;
  std::vector<Clip> clips;
  if (source.use_cache) ds.from_cache = read_cached_clips(cache_file, &clips, &ds.skipped);
  if (ds.from_cache && options.verbose) {
    std::fprintf(stderr, "mf dataset: %zu clips from cache %s (%.2f s)\n", clips.size(), cache_file.c_str(),
                 seconds_since(t0));
  }
  if (!ds.from_cache) {
    if (!source.is_folder) files = list_bvh_files(ensure_extracted(source.path, source.cache_dir, source_key, options.verbose));
    if (files.empty()) throw InputError("no .bvh file in " + options.source);
    parse_clips(files, options, &clips, &ds.skipped);
    if (source.use_cache && !clips.empty()) write_cached_clips(cache_file, clips, ds.skipped, options.verbose);
  }
  if (clips.empty()) throw no_usable_clip(options.source, ds.skipped);
  split_clips(std::move(clips), options.validation_percent, &ds);
  if (options.verbose)
    std::fprintf(stderr, "mf dataset: %zu train, %zu validation, %zu skipped clips in %.2f s\n", ds.train.size(),
                 ds.validation.size(), ds.skipped.size(), seconds_since(t0));
  return ds;
}

std::vector<SourceBvhFile> list_source_bvh_files(const std::string& source_path, const std::string& cache_dir,
                                                 bool verbose) {
  DatasetOptions options;
  options.source = source_path;
  options.cache_dir = cache_dir;
  options.use_cache = false;
  const ResolvedSource source = resolve_source(options);
  const fs::path root =
      source.is_folder ? source.path : ensure_extracted(source.path, source.cache_dir, archive_key(source.path), verbose);
  std::vector<SourceBvhFile> out;
  for (const SourceFile& f : list_bvh_files(root)) out.push_back({f.rel, f.path.string()});
  if (out.empty()) throw InputError("no .bvh file in " + source_path);
  return out;
}

std::vector<Window> make_windows(const std::vector<Clip>& clips, int length, int stride, bool keep_short) {
  if (length < 1) throw InputError("window length must be at least 1, got " + std::to_string(length));
  if (stride < 1) throw InputError("window stride must be at least 1, got " + std::to_string(stride));
  std::vector<Window> windows;
  for (size_t c = 0; c < clips.size(); ++c) {
    const int frames = clips[c].motion.num_frames();
    if (frames <= 0) continue;
    if (frames < length) {
      if (keep_short) windows.push_back({static_cast<int>(c), 0, frames});
      continue;
    }
    for (long long start = 0; start + length <= frames; start += stride)
      windows.push_back({static_cast<int>(c), static_cast<int>(start), length});
  }
  return windows;
}

}  // namespace mf
