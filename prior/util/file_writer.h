// The one safe file writer: every file motionfield writes (motions in every
// format, alternatives, constraint reports, model files) goes through it, and
// a job's outputs are checked together against each other and its inputs
// (docs/RELIABILITY.md, "Outputs").
//
// A regular file (or a new one) is written to a temporary file with a unique
// name beside it (`.NAME.XXXXXXXX.tmp`, created exclusively, so no file of the
// user's is ever overwritten or removed) and renamed over it, so a reader sees
// the old file or the whole new one, never half of one. Anything else that
// exists (a character device like /dev/null or /dev/full, a FIFO, a socket)
// and the names of open descriptors (/dev/stdout, /dev/fd/N, /proc/self/fd/N)
// are written in place and stay what they are. A symbolic link is followed: the file
// it points to is replaced and the link kept. Every failure is a FileError
// "cannot write <path>: <reason>" (strerror: "No space left on device",
// "Permission denied", ...), and leaves no temporary file behind.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "prior/util/binary_io.h"

namespace mf {

/// Writes `size` bytes to `path` as the header says, at once.
void write_file_atomically(const std::string& path, const void* data, size_t size);
inline void write_file_atomically(const std::string& path, const std::vector<uint8_t>& bytes) {
  write_file_atomically(path, bytes.data(), bytes.size());
}

/// The files of one job (or of a batch of jobs): what it reads and what it
/// writes, checked together before anything runs, and its outputs written
/// together at the end.
///
/// No two outputs, and no output and input, may be the same file: files
/// that exist are compared by device and inode after following symbolic
/// links (a.bvh, ./a.bvh, a hard link and a symbolic link all match), files
/// that do not exist yet by their absolute name with the links of their
/// directories resolved. Devices, FIFOs and sockets are never "the same
/// file" (/dev/null may take every output).
///
/// The outputs are staged: write() puts a regular file's bytes into its
/// temporary file at once (where a full disk or a read-only directory
/// shows) and keeps a device's bytes; commit() writes the devices in place,
/// then renames every temporary file over its target. A failure anywhere
/// before the renames, or destroying the set without commit(), removes
/// every temporary file: a failed job leaves none of its outputs behind
/// (and the files they would have replaced untouched).
class OutputFiles {
 public:
  OutputFiles();
  ~OutputFiles();
  OutputFiles(const OutputFiles&) = delete;
  OutputFiles& operator=(const OutputFiles&) = delete;

  /// A file the job reads, named as the user named it; `role` says what it
  /// is ("input", "rig map file", ...). An empty path adds nothing. Throws
  /// InputError "the <output role> O is the <role> I: refusing to overwrite
  /// it (name another output file)" when it is an output added before.
  void add_input(const std::string& path, const std::string& role);

  /// A file the job writes; `role` says what it is ("output", "alternative",
  /// "report"). Throws FileError "cannot write O: it is a directory" or
  /// "cannot write O: directory D does not exist", and InputError when it is
  /// an input ("the <role> O is the <input role> I: refusing to overwrite it
  /// (name another output file)") or another output ("the <role> O is also
  /// the <other role> P: ... one file written twice ..."). Nothing is added
  /// when it throws.
  void add_output(const std::string& path, const std::string& role);

  /// Adds every file of `job` (a set of one job, checked by its own
  /// add_input and add_output) at once, or none: throws InputError when one
  /// is the same file as one of this set's and either of them is written:
  /// "<label> already writes O: refusing to overwrite another job's output
  /// (give each job its own output files)", "<label> reads O: ...", "<label>
  /// writes I, which this job reads: ...", where <label> names the earlier
  /// job ("line 2"). The files keep `label`.
  void merge(const OutputFiles& job, const std::string& label);

  /// Stages the bytes of output `path` (as given to add_output). Throws
  /// FileError "cannot write <path>: <reason>", InputError when `path` is no
  /// output of the set or the set was committed.
  void write(const std::string& path, const void* data, size_t size);

  /// Writes the staged devices in place, then moves every staged file into
  /// place. Throws FileError naming the file and the reason; the files not
  /// yet in place are removed. A set is committed once.
  void commit();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace mf
