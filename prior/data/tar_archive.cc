#include "prior/data/tar_archive.h"

#include <archive.h>
#include <archive_entry.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <memory>
#include <system_error>
#include <vector>

#include "prior/motion/errors.h"

namespace mf {

namespace {

namespace fs = std::filesystem;

using ArchivePtr = std::unique_ptr<archive, decltype(&archive_read_free)>;

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

class Extraction {
 public:
  Extraction(const std::string& archive_path, const fs::path& into)
      : path_(archive_path), into_(into), reader_(archive_read_new(), archive_read_free) {}

  void run() {
    if (!reader_) fail("cannot allocate an archive reader");
    archive_read_support_filter_xz(reader_.get());
    archive_read_support_filter_gzip(reader_.get());
    archive_read_support_format_tar(reader_.get());
    if (archive_read_open_filename(reader_.get(), path_.c_str(), 1 << 16) != ARCHIVE_OK) fail(library_error());
    archive_entry* entry = nullptr;
    for (;;) {
      const int status = archive_read_next_header(reader_.get(), &entry);
      if (status == ARCHIVE_EOF) break;
      if (status < ARCHIVE_WARN) fail(library_error());
      const fs::path relative = safe_relative_path(archive_entry_pathname(entry));
      // Hard links carry no data in a tar file; symbolic links and devices are not clips.
      if (archive_entry_filetype(entry) != AE_IFREG || archive_entry_hardlink(entry) != nullptr) continue;
      write_data(into_ / relative);
    }
  }

 private:
  [[noreturn]] void fail(const std::string& why) const { throw InputError("cannot extract " + path_ + ": " + why); }

  std::string library_error() const {
    const char* message = archive_error_string(reader_.get());
    return message ? message : "unknown libarchive error";
  }

  // The entry's path below the extraction folder; refuses absolute paths and
  // ".." components, which could write outside it.
  fs::path safe_relative_path(const char* name) const {
    if (name == nullptr || *name == '\0') fail("an entry has no name");
    const fs::path p(name);
    bool unsafe = p.has_root_path();
    for (const fs::path& part : p) unsafe = unsafe || part == "..";
    if (unsafe) fail("refusing the entry '" + std::string(name) + "' (an absolute path or a '..' component)");
    return p.lexically_normal();
  }

  void write_data(const fs::path& target) {
    std::error_code ec;
    fs::create_directories(target.parent_path(), ec);
    if (ec) fail("cannot create " + target.parent_path().string() + ": " + ec.message());
    std::ofstream out(target, std::ios::binary | std::ios::trunc);
    if (!out) fail("cannot write " + target.string());
    buffer_.resize(1 << 16);
    for (;;) {
      const la_ssize_t n = archive_read_data(reader_.get(), buffer_.data(), buffer_.size());
      if (n == 0) break;
      if (n < 0) fail(library_error());
      out.write(buffer_.data(), static_cast<std::streamsize>(n));
    }
    out.close();
    if (!out) fail("cannot write " + target.string());
  }

  std::string path_;
  fs::path into_;
  ArchivePtr reader_;
  std::vector<char> buffer_;
};

}  // namespace

bool is_tar_archive_name(const std::string& file_name) {
  std::string n = file_name;
  for (char& c : n) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char* suffix : {".tar", ".tar.xz", ".txz", ".tar.gz", ".tgz"}) {
    if (ends_with(n, suffix)) return true;
  }
  return false;
}

void extract_tar_archive(const std::string& archive, const std::string& into) { Extraction(archive, into).run(); }

}  // namespace mf
