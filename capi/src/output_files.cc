// The output sets of motionfield.h: a job's files checked together and its
// outputs written together, over prior/util/file_writer.h.
#include "capi/src/capi_internal.h"
#include "prior/util/file_writer.h"

struct mf_output_set {
  mf::OutputFiles files;
};

using mf::capi::ApiError;
using mf::capi::guard;
using mf::capi::require;

extern "C" {

int mf_output_set_create(mf_output_set** out) {
  return guard([&] {
    require(out, "out");
    *out = new mf_output_set();
  });
}

void mf_output_set_destroy(mf_output_set* set) { delete set; }

int mf_output_set_add_input(mf_output_set* set, const char* path, const char* role) {
  return guard([&] {
    require(set, "set");
    require(path, "path");
    require(role, "role");
    set->files.add_input(path, role);
  });
}

int mf_output_set_add_output(mf_output_set* set, const char* path, const char* role) {
  return guard([&] {
    require(set, "set");
    require(path, "path");
    require(role, "role");
    set->files.add_output(path, role);
  });
}

int mf_output_set_merge(mf_output_set* set, const mf_output_set* job, const char* label) {
  return guard([&] {
    require(set, "set");
    require(job, "job");
    require(label, "label");
    if (set == job) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "a set cannot be merged into itself");
    set->files.merge(job->files, label);
  });
}

int mf_output_set_write(mf_output_set* set, const char* path, const void* data, size_t size) {
  return guard([&] {
    require(set, "set");
    require(path, "path");
    if (!data && size != 0) throw ApiError(MF_ERROR_INVALID_ARGUMENT, "data is NULL");
    set->files.write(path, data, size);
  });
}

int mf_output_set_commit(mf_output_set* set) {
  return guard([&] {
    require(set, "set");
    set->files.commit();
  });
}

}  // extern "C"
