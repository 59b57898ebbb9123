// The archives of the data pipeline (prior/data/dataset.h): tar files, plain
// or compressed with xz or gzip, read with libarchive (no external program).
#pragma once

#include <string>

namespace mf {

/// True when `file_name` ends in .tar, .tar.xz, .txz, .tar.gz or .tgz (any case).
bool is_tar_archive_name(const std::string& file_name);

/// Writes every regular file of the tar archive `archive` (the compression is
/// detected from the content) below the existing folder `into`, at its path in
/// the archive ("./a/b.bvh" and "a/b.bvh" both give into/a/b.bvh), creating the
/// folders on the way. Other entries (folders, links, devices) are skipped.
/// Throws mf::InputError "cannot extract <archive>: <reason>" when the archive
/// cannot be read, is damaged or truncated, or holds an entry whose path is
/// absolute or has a ".." component (checked before anything of that entry is
/// written). Files written before an error stay: extract into a temporary
/// folder and remove it on failure.
void extract_tar_archive(const std::string& archive, const std::string& into);

}  // namespace mf
