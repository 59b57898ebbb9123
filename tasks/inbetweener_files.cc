#include "tasks/inbetweener_files.h"

#include <filesystem>

#include "prior/inbetween/inbetweener.h"
#include "prior/motion/errors.h"

namespace mf {

std::string inbetweener_file_name(const std::string& kind) {
  if (kind == kTwoStageKind) return kTwoStageFileName;
  if (kind == kCitlKind) return kCitlFileName;
  throw InputError("unknown transformer kind '" + kind + "' (available: twostage, citl)");
}

std::string inbetweener_title(const std::string& kind) {
  return kind == kCitlKind ? "CITL transformer" : kind == kTwoStageKind ? "two-stage transformer" : kind;
}

std::string inbetweener_path_next_to(const std::string& prior_path, const std::string& kind) {
  return (std::filesystem::path(prior_path).parent_path() / inbetweener_file_name(kind)).string();
}

std::shared_ptr<const InbetweenModel> load_frozen_inbetweener(const std::string& path, const std::string& kind) {
  std::unique_ptr<InbetweenModel> model = load_inbetweener(path);
  if (model->kind() != kind)
    throw InputError(path + " holds a '" + model->kind() + "' model, not the expected '" + kind + "'");
  model->set_requires_grad(false);
  model->train(false);
  return std::shared_ptr<const InbetweenModel>(std::move(model));
}

std::string missing_inbetweener_message(const std::string& what, const std::string& kind) {
  return what + " needs models/" + inbetweener_file_name(kind) + " (the " + inbetweener_title(kind) +
         "), and it is not loaded: put it next to the prior's model file";
}

const InbetweenModel& require_inbetweener(const TaskContext& ctx, const std::string& kind, const std::string& what) {
  const InbetweenModel* model = ctx.inbetweener(kind);
  if (!model) throw ModelMissingError(missing_inbetweener_message(what, kind));
  return *model;
}

}  // namespace mf
