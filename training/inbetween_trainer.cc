#include "training/inbetween_trainer.h"

#include <ATen/ATen.h>
#include <ATen/Parallel.h>
#include <torch/types.h>
#include <torch/nn/utils/clip_grad.h>
#include <torch/optim/adam.h>
#include <torch/serialize.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <random>

#include "prior/inbetween/inbetweener.h"
#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "training/keyframe_losses.h"
#include "training/salient_poses.h"
#include "training/trainer_util.h"
#include "prior/util/threads.h"

namespace mf {

namespace {

namespace fs = std::filesystem;

struct Sample {
  int clip = 0;
  int start = 0;
  int length = 0;
  int gap_begin = -1;        // transitions (keyframe kinds): the last context frame; -1 otherwise
  std::vector<float> known;  // [length, J + 1]
};

// The transition protocol of keyframe kinds (inbetween_trainer.h); off for the others.
struct TransitionProtocol {
  bool on = false;
  int context = 10, min_transition = 5, max_transition = 90;
  int min_spacing = 5;  // the model's, for the Salient Poses scores
};

struct Batch {
  InbetweenBatch input;
  at::Tensor target;      // [B, T, D] raw pose features (padding repeats the last frame)
  at::Tensor contacts;    // [B, T, F]
  at::Tensor scores;      // transitions: [B, T] Salient Poses scores
  at::Tensor score_mask;  // transitions: [B, T] the frames strictly inside the transition
};

// Joints that belong to the legs: the feet, their ancestors below the root and
// their descendants.
std::vector<bool> leg_joints(const RigInfo& rig) {
  const Skeleton& sk = rig.skeleton;
  std::vector<bool> leg(sk.num_joints(), false);
  for (int f : rig.foot_joints) {
    for (int j = f; j > 0; j = sk.parents[j]) leg[j] = true;
  }
  // Descendants of feet (toes), transitively.
  for (int j = 1; j < sk.num_joints(); ++j) {
    for (int a = sk.parents[j]; a > 0; a = sk.parents[a]) {
      if (std::find(rig.foot_joints.begin(), rig.foot_joints.end(), a) != rig.foot_joints.end()) leg[j] = true;
    }
  }
  return leg;
}

class Sampler {
 public:
  Sampler(const std::vector<Clip>& clips, const RigInfo& rig, int window, int min_length,
          const TransitionProtocol& transitions)
      : clips_(clips), J_(rig.num_joints()), window_(window), min_length_(std::min(min_length, window)),
        transitions_(transitions), legs_(leg_joints(rig)) {
    for (size_t c = 0; c < clips.size(); ++c) {
      const int n = clips[c].motion.num_frames();
      if (n >= 2) {
        usable_.push_back(static_cast<int>(c));
        cumulative_.push_back((cumulative_.empty() ? 0.0 : cumulative_.back()) + n);
      }
    }
  }
  bool empty() const { return usable_.empty(); }
  double total_frames() const { return cumulative_.empty() ? 0.0 : cumulative_.back(); }

  Sample draw(std::mt19937_64& rng) const {
    std::uniform_real_distribution<double> u(0.0, total_frames());
    const size_t k = std::upper_bound(cumulative_.begin(), cumulative_.end(), u(rng)) - cumulative_.begin();
    Sample s;
    s.clip = usable_[std::min(k, usable_.size() - 1)];
    const int n = clips_[s.clip].motion.num_frames();
    if (transitions_.on) return draw_transition(s, n, rng);
    const int L = std::uniform_int_distribution<int>(min_length_, window_)(rng);
    s.length = std::min(L, n);
    s.start = n > s.length ? std::uniform_int_distribution<int>(0, n - s.length)(rng) : 0;
    s.known = known_pattern(s.length, rng);
    return s;
  }

 private:
  // Context frames, a transition, the target (the clip's length when shorter).
  Sample draw_transition(Sample s, int n, std::mt19937_64& rng) const {
    const TransitionProtocol& p = transitions_;
    const int gap = std::uniform_int_distribution<int>(p.min_transition, p.max_transition)(rng);
    s.length = std::min({p.context + gap + 1, n, window_});
    s.start = n > s.length ? std::uniform_int_distribution<int>(0, n - s.length)(rng) : 0;
    const int context = std::max(1, std::min(p.context, s.length - 2));
    s.gap_begin = context - 1;
    const int K = J_ + 1;
    s.known.assign(static_cast<size_t>(s.length) * K, 0.0f);
    std::fill(s.known.begin(), s.known.begin() + context * K, 1.0f);
    std::fill(s.known.end() - K, s.known.end(), 1.0f);
    return s;
  }

  std::vector<float> known_pattern(int n, std::mt19937_64& rng) const {
    const int K = J_ + 1;
    std::vector<float> known(static_cast<size_t>(n) * K, 0.0f);
    auto full = [&](int t) { std::fill(known.begin() + t * K, known.begin() + (t + 1) * K, 1.0f); };
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double kind = u(rng);
    full(0);
    full(n - 1);
    if (kind < 0.5) {
      const int c = std::uniform_int_distribution<int>(1, 10)(rng);
      for (int t = 1; t < std::min(c, n - 1); ++t) full(t);
      return known;
    }
    std::vector<int> keys;
    if (u(rng) < 0.5) {
      std::uniform_int_distribution<int> spacing(2, 40);
      for (int t = spacing(rng); t < n - 1; t += spacing(rng)) keys.push_back(t);
    } else {
      const double p = 0.02 + 0.28 * u(rng);
      for (int t = 1; t < n - 1; ++t)
        if (u(rng) < p) keys.push_back(t);
    }
    const bool partial = kind >= 0.9;
    for (int t : keys) {
      if (!partial || u(rng) < 0.5) {
        full(t);
        continue;
      }
      float* row = known.data() + static_cast<size_t>(t) * K;
      const double which = u(rng);
      if (which < 1.0 / 3) {
        row[0] = 1.0f;  // root only
        row[J_] = 1.0f;
        continue;
      }
      for (int j = 0; j < J_; ++j) row[j] = which < 2.0 / 3 ? (legs_[j] ? 1.0f : 0.0f) : (u(rng) < 0.5 ? 1.0f : 0.0f);
      row[J_] = u(rng) < 0.5 ? 1.0f : 0.0f;
    }
    return known;
  }

  const std::vector<Clip>& clips_;
  int J_, window_, min_length_;
  TransitionProtocol transitions_;
  std::vector<bool> legs_;
  std::vector<int> usable_;
  std::vector<double> cumulative_;
};

// Foot contacts of whole clips (they do not depend on the canonical frame).
std::vector<at::Tensor> clip_contacts(const std::vector<Clip>& clips, const RigInfo& rig, double fps) {
  at::NoGradGuard no_grad;
  std::vector<at::Tensor> out;
  for (const Clip& c : clips) {
    const int n = c.motion.num_frames();
    if (n < 2 || rig.num_feet() == 0) {
      out.emplace_back();
      continue;
    }
    WindowTensors w = window_tensors(c.motion, 0, n, rig, 0);
    out.push_back(gmp_targets(w.local_rotations, w.root_positions, rig, fps).contacts.squeeze(0));
  }
  return out;
}

// Salient Poses scores [1, T] of a transition sample's frames gap_begin .. length - 1
// and the mask [1, T] of the frames strictly inside the transition.
void transition_scores(const WindowTensors& w, const Sample& s, const RigInfo& rig, int min_spacing, int T,
                       at::Tensor* scores, at::Tensor* mask) {
  *scores = at::zeros({1, T});
  *mask = at::zeros({1, T});
  const int n = s.length - s.gap_begin;
  if (s.gap_begin < 0 || n < 3) return;
  at::Tensor offsets = offsets_tensor(rig.skeleton);
  at::Tensor g = forward_kinematics(rig.skeleton.parents, offsets, w.local_rotations.narrow(1, s.gap_begin, n),
                                    w.root_positions.narrow(1, s.gap_begin, n))
                     .positions.squeeze(0);  // [n, J, 3]
  scores->narrow(1, s.gap_begin, n).copy_(training::salient_scores(g, min_spacing).unsqueeze(0));
  mask->narrow(1, s.gap_begin + 1, n - 2).fill_(1.0);
}

Batch make_batch(const std::vector<Clip>& clips, const std::vector<at::Tensor>& contacts,
                 const std::vector<Sample>& samples, size_t begin, size_t end, const RigInfo& rig,
                 const TransitionProtocol& transitions) {
  at::NoGradGuard no_grad;
  const int J = rig.num_joints();
  int T = 0;
  for (size_t i = begin; i < end; ++i) T = std::max(T, samples[i].length);
  std::vector<at::Tensor> targets, knowns, valids, feet, trajectories, scores, score_masks;
  for (size_t i = begin; i < end; ++i) {
    const Sample& s = samples[i];
    WindowTensors w = window_tensors(clips[s.clip].motion, s.start, s.length, rig, 0);
    at::Tensor pose = pose_features(w.local_rotations, w.root_positions).squeeze(0);  // [n, D]
    targets.push_back(training::padded_slice(pose, 0, s.length, T));
    if (transitions.on) {
      at::Tensor trajectory =
          trajectory_features(w.local_rotations.select(2, 0), w.root_positions, rig.root_forward).squeeze(0);
      trajectories.push_back(training::padded_slice(trajectory, 0, s.length, T));
      scores.emplace_back();
      score_masks.emplace_back();
      transition_scores(w, s, rig, transitions.min_spacing, T, &scores.back(), &score_masks.back());
    }
    at::Tensor known = at::zeros({1, T, J + 1});
    known.narrow(1, 0, s.length).copy_(at::from_blob(const_cast<float*>(s.known.data()), {1, s.length, J + 1},
                                                     at::kFloat));
    knowns.push_back(known);
    at::Tensor v = at::zeros({1, T});
    v.narrow(1, 0, s.length).fill_(1.0);
    valids.push_back(v);
    if (rig.num_feet() > 0) feet.push_back(training::padded_slice(contacts[s.clip], s.start, s.length, T));
  }
  Batch b;
  b.target = at::cat(targets, 0);
  b.input.known = at::cat(knowns, 0);
  b.input.valid = at::cat(valids, 0);
  b.input.pose = b.target * known_channel_mask(b.input.known, J);
  if (!feet.empty()) b.contacts = at::cat(feet, 0);
  if (!trajectories.empty()) {
    b.input.trajectory = at::cat(trajectories, 0);
    b.scores = at::cat(scores, 0);
    b.score_mask = at::cat(score_masks, 0);
  }
  return b;
}

struct StepLosses {
  std::vector<at::Tensor> stages;  // inbetween_pose_loss per stage
  InbetweenLossParts last;         // parts of the last stage
  at::Tensor contact;              // undefined without contacts
  at::Tensor total;
};

// Keyframe kinds: training/keyframe_losses.h; stages = KeyframeNet's and RefineNet's totals.
StepLosses keyframe_step_losses(const InbetweenModel& model, const Batch& b, const InbetweenOutput& out) {
  training::KeyframeTargets t{b.target, b.input.valid, b.input.trajectory, b.scores, b.score_mask, b.contacts};
  training::KeyframeLosses k = training::keyframe_losses(model, out, t);
  StepLosses L;
  L.stages = {k.keyframe_total, k.refine_total};
  L.last = k.refine_parts;
  L.contact = k.contact;
  L.total = k.total;
  return L;
}

StepLosses compute_losses(const InbetweenModel& model, const Batch& b, double contact_weight) {
  InbetweenOutput out = model.forward(b.input);
  if (out.stages.empty()) throw std::runtime_error("in-betweener returned no stage");
  if (out.keyframe_logits.defined() && b.scores.defined()) return keyframe_step_losses(model, b, out);
  StepLosses L;
  L.total = at::zeros({});
  for (size_t k = 0; k < out.stages.size(); ++k) {
    InbetweenLossParts parts;
    at::Tensor l = inbetween_pose_loss(model, out.stages[k], b.target, b.input.valid, &parts);
    L.stages.push_back(l);
    L.total = L.total + l;
    if (k + 1 == out.stages.size()) L.last = parts;
  }
  if (out.contact_logits.defined() && b.contacts.defined()) {
    at::Tensor bce =
        at::binary_cross_entropy_with_logits(out.contact_logits, b.contacts, {}, {}, at::Reduction::None);
    L.contact = training::masked_mean(bce, b.input.valid);
    L.total = L.total + contact_weight * L.contact;
  }
  return L;
}

double item(const at::Tensor& t) { return t.defined() ? t.item<double>() : 0.0; }

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

void check_options(const InbetweenTrainingOptions& o) {
  if (o.out_dir.empty()) throw InputError("train: an output directory is required");
  if (o.batch < 1 || o.min_length < 2 || !(o.max_minutes > 0) || !(o.lr > 0) || o.validation_windows < 0 ||
      !(o.warmup >= 0 && o.warmup < 1)) {
    throw InputError(
        "train: batch, time budget and learning rate must be positive, min length at least 2, warm-up in [0, 1)");
  }
}

// A model of `from`'s kind with the hyperparameters `hp` that holds every
// parameter of `from` under the same name and shape, its statistics too, and
// the parameters only `hp` has freshly initialised (a part added to a trained
// model, e.g. the two-stage "interp_input" gate). Anything else is refused.
std::unique_ptr<InbetweenModel> grown_model(const InbetweenModel& from, const std::map<std::string, double>& hp,
                                            const std::string& what) {
  std::unique_ptr<InbetweenModel> model = make_inbetweener(from.kind(), hp, from.rig());
  std::map<std::string, at::Tensor> target;
  for (auto& [name, t] : model->named_parameters()) target[name] = t;
  torch::NoGradGuard no_grad;
  for (const auto& [name, t] : from.named_parameters()) {
    auto it = target.find(name);
    if (it == target.end() || !it->second.sizes().equals(t.sizes())) {
      throw InputError("train: " + what + " with other hyperparameters: its parameter " + name +
                       " has no counterpart of the same shape in " + model->describe());
    }
    it->second.copy_(t);
    target.erase(it);
  }
  if (target.empty()) {
    throw InputError("train: " + what + " with other hyperparameters than the file's (" + from.describe() +
                     ") that add no parameter");
  }
  model->stats() = from.stats();
  std::cerr << "train: " << what << ": every parameter taken, " << target.size() << " new (";
  for (auto it = target.begin(); it != target.end(); ++it) std::cerr << (it == target.begin() ? "" : ", ") << it->first;
  std::cerr << ")\n";
  return model;
}

// A new model of o.kind, the checkpoint's when resuming, or o.init_from's
// (checked against the options).
std::unique_ptr<InbetweenModel> load_or_make_model(const InbetweenTrainingOptions& o, const Dataset& data,
                                                   const training::RunFiles& files, bool resuming) {
  at::manual_seed(o.seed);
  if (!resuming && o.init_from.empty()) {
    return make_inbetweener(o.kind, o.hyperparameters, training::measure_training_rig(data));
  }
  const std::string what = resuming ? "--resume" : "--init " + o.init_from;
  std::unique_ptr<InbetweenModel> model = load_inbetweener(resuming ? files.last_model : o.init_from);
  if (model->kind() != o.kind) {
    throw InputError("train: " + what + ": the file holds a '" + model->kind() + "' model, not '" + o.kind + "'");
  }
  auto hp = model->hyperparameters();
  bool same = true;
  for (const auto& [k, v] : o.hyperparameters) {
    auto it = hp.find(k);
    if (it == hp.end() || it->second != v) same = false;
    hp[k] = v;
  }
  if (same) return model;
  if (resuming) throw InputError("train: --resume with other hyperparameters than the file's (" + model->describe() + ")");
  return grown_model(*model, hp, what);
}

// The training clips' frame rate and skeleton must be the model's.
void check_data_fits(const InbetweenModel& model, const Dataset& data) {
  for (const Clip& c : data.train) {
    if (std::abs(c.motion.fps - model.fps()) > 1e-3) {
      throw InputError("train: clip " + c.name + " is at " + std::to_string(c.motion.fps) + " fps, the model at " +
                       std::to_string(model.fps()) + " fps");
    }
  }
  if (!model.rig().skeleton.same_as(data.skeleton)) {
    throw InputError("train: the skeleton of the model to continue (--resume or --init) differs from the data's");
  }
}

// The transition protocol for keyframe kinds (their "min_spacing" hyperparameter sets the scores').
TransitionProtocol transition_protocol(const InbetweenTrainingOptions& o, const InbetweenModel& model) {
  TransitionProtocol p;
  p.on = model.kind() == kKeyframeKind;
  if (!p.on) return p;
  if (o.context < 1 || o.min_transition < 1 || o.max_transition < o.min_transition ||
      o.context + o.max_transition + 1 > model.window()) {
    throw InputError("train: need context >= 1, 1 <= min transition <= max transition and context + max transition "
                     "+ 1 <= the model's window (" + std::to_string(model.window()) + ")");
  }
  p.context = o.context;
  p.min_transition = o.min_transition;
  p.max_transition = o.max_transition;
  const auto hp = model.hyperparameters();
  auto it = hp.find("min_spacing");
  if (it != hp.end()) p.min_spacing = static_cast<int>(it->second);
  return p;
}

// Training-loss sums of one epoch: total, one per stage, contact.
struct EpochSums {
  explicit EpochSums(size_t stages) : values(stages + 2, 0.0) {}
  std::vector<double> values;
  int count = 0;
  double mean(size_t k) const { return values[k] / count; }
  double total() const { return mean(0); }
  double contact() const { return mean(values.size() - 1); }
};

// Validation losses per frame of the last stage (score, parts, contact) and per stage.
struct Validation {
  double score = 0, rot = 0, pos = 0, root = 0, contact = 0;
  std::vector<double> stages;
};

// One training run: the set-up in the constructor, then train().
class InbetweenRun {
 public:
  explicit InbetweenRun(const InbetweenTrainingOptions& o);
  InbetweenTrainingResult train();

 private:
  void measure_pose_statistics();
  void make_validation_set();
  void open_log() const;
  void print_setup() const;
  double minutes_now() const { return base_minutes_ + seconds_between(t0_, Clock::now()) / 60.0; }
  // The fraction of the budget used (time, or steps with max_steps).
  double progress();
  // Returns true when the budget is used up.
  bool train_epoch(EpochSums* sums);
  void train_step(EpochSums* sums);
  void print_progress(const EpochSums& sums);
  Validation validate();
  void end_epoch(const EpochSums& sums, const Validation& v);
  void save_checkpoint();

  const InbetweenTrainingOptions& o_;
  const Clock::time_point t0_;
  const training::RunFiles files_;
  training::DataParallel dp_;
  Dataset data_;
  bool resuming_ = false;
  const training::RunFiles resume_from_;  // files_, or on ranks > 0 rank 0's checkpoint copied
  std::unique_ptr<InbetweenModel> model_;
  TransitionProtocol transitions_;
  Sampler train_sampler_, val_sampler_;
  std::vector<at::Tensor> train_contacts_, val_contacts_;
  std::vector<Batch> val_batches_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
  training::TrainerState state_;
  std::vector<std::string> stage_names_;
  double base_minutes_ = 0;
  int epoch_steps_ = 0;
  bool profile_ = std::getenv("MF_PROFILE") != nullptr;
  int64_t first_step_ = 0;
  Clock::time_point run_start_, last_checkpoint_, last_progress_;
  double lr_;
};

InbetweenRun::InbetweenRun(const InbetweenTrainingOptions& o)
    : o_(o),
      t0_(Clock::now()),
      files_(o.out_dir),
      dp_(o.distributed),
      data_(training::load_training_data(o.data, o.cache_dir, o.max_train_clips, 0.0, o.augmentation,
                                         o.verbose && dp_.writes())),
      resume_from_(dp_.resume_files(files_, o.resume, &resuming_)),
      model_(load_or_make_model(o, data_, resume_from_, resuming_)),
      transitions_(transition_protocol(o, *model_)),
      train_sampler_(data_.train, model_->rig(), model_->window(), o.min_length, transitions_),
      val_sampler_(data_.validation, model_->rig(), model_->window(), o.min_length, transitions_),
      lr_(o.lr) {
  check_data_fits(*model_, data_);
  if (train_sampler_.empty()) throw InputError("train: no training clip has 2 frames or more");
  train_contacts_ = clip_contacts(data_.train, model_->rig(), model_->fps());
  val_contacts_ = clip_contacts(data_.validation, model_->rig(), model_->fps());
  // An --init model keeps its statistics: its weights were trained on them.
  if (!resuming_ && o.init_from.empty()) measure_pose_statistics();
  make_validation_set();
  model_->set_requires_grad(true);
  model_->train(true);
  optimizer_ = std::make_unique<torch::optim::Adam>(model_->parameters(), torch::optim::AdamOptions(o.lr));
  if (resuming_) {
    torch::load(*optimizer_, resume_from_.last_optim);
    state_ = training::load_trainer_state(resume_from_.last_state);
    dp_.check_resumed_world_size(state_);
  } else {
    // Every rank starts from rank 0's weights and statistics.
    std::vector<at::Tensor> shared = model_->parameters();
    shared.insert(shared.end(), {model_->stats().pose_mean, model_->stats().pose_std});
    dp_.broadcast(shared);
  }
  state_.world_size = dp_.world_size();
  stage_names_ = model_->stage_names();
  if (dp_.writes() && (!resuming_ || !fs::exists(files_.log))) open_log();
  base_minutes_ = state_.minutes;
  const double mean_length = transitions_.on
                                 ? transitions_.context + 0.5 * (o.min_transition + o.max_transition) + 1
                                 : 0.5 * (std::min(o.min_length, model_->window()) + model_->window());
  const double global_batch = static_cast<double>(o.batch) * dp_.world_size();
  epoch_steps_ = o.epoch_steps > 0
                     ? o.epoch_steps
                     : std::max(1, static_cast<int>(train_sampler_.total_frames() / (mean_length * global_batch)));
  if (o.verbose && dp_.writes()) print_setup();
}

// Pose statistics over sampled training windows (root positions depend on the
// canonical frame, so measure them as the model will see them).
void InbetweenRun::measure_pose_statistics() {
  at::NoGradGuard no_grad;
  std::mt19937_64 rng(o_.seed * 31 + 7);
  std::vector<Sample> samples;
  const int n = std::max(64, std::min(2000, static_cast<int>(train_sampler_.total_frames() / 32)));
  for (int i = 0; i < n; ++i) samples.push_back(train_sampler_.draw(rng));
  std::vector<at::Tensor> frames;
  for (size_t i = 0; i < samples.size(); i += 64) {
    Batch b = make_batch(data_.train, train_contacts_, samples, i, std::min(samples.size(), i + 64), model_->rig(), transitions_);
    frames.push_back(b.target.flatten(0, 1).index({b.input.valid.flatten() > 0.5}));
  }
  at::Tensor all = at::cat(frames, 0).to(at::kDouble);
  model_->stats().pose_mean = all.mean(0).to(at::kFloat);
  model_->stats().pose_std = all.std(0).clamp_min(1e-3).to(at::kFloat);
}

// A fixed validation set: the same windows every epoch and run.
void InbetweenRun::make_validation_set() {
  if (val_sampler_.empty()) return;
  std::mt19937_64 rng(0x5eed5eedULL);
  std::vector<Sample> samples;
  for (int i = 0; i < o_.validation_windows; ++i) samples.push_back(val_sampler_.draw(rng));
  for (size_t i = 0; i < samples.size(); i += 64) {
    val_batches_.push_back(
        make_batch(data_.validation, val_contacts_, samples, i, std::min(samples.size(), i + 64), model_->rig(),
                   transitions_));
  }
}

void InbetweenRun::open_log() const {
  std::ofstream log(files_.log);
  log << "epoch,step,minutes,lr,steps_per_s,train_loss";
  for (const auto& s : stage_names_) log << ",train_" << s;
  log << ",train_contact,val_score,val_rot,val_pos_cm,val_root_cm";
  for (const auto& s : stage_names_) log << ",val_" << s;
  log << ",val_contact,best\n";
}

void InbetweenRun::print_setup() const {
  std::fprintf(stderr,
               "train %s: %zu training clips, %zu validation clips (%zu validation windows), %d threads; %s; %lld "
               "parameters; epoch = %d steps%s%s\n",
               model_->kind().c_str(), data_.train.size(), data_.validation.size(),
               static_cast<size_t>(o_.validation_windows), std::max(1, o_.threads), model_->describe().c_str(),
               static_cast<long long>(model_->num_parameters()), epoch_steps_, resuming_ ? "; resumed" : "",
               dp_.distributed() ? ("; " + std::to_string(dp_.world_size()) + " processes").c_str() : "");
  std::fprintf(stderr, "train: set-up (data, statistics, validation set) in %.1f s\n",
               seconds_between(t0_, Clock::now()));
}

InbetweenTrainingResult InbetweenRun::train() {
  first_step_ = state_.step;
  run_start_ = last_checkpoint_ = last_progress_ = Clock::now();
  bool done = false;
  while (!done && state_.epoch < o_.max_epochs) {
    EpochSums sums(stage_names_.size());
    done = train_epoch(&sums);
    if (sums.count == 0) break;
    end_epoch(sums, validate());
  }
  InbetweenTrainingResult result;
  result.epochs = state_.epoch;
  result.steps = state_.step;
  result.minutes = state_.minutes;
  result.steps_per_second = (state_.step - first_step_) / std::max(1e-9, seconds_between(run_start_, Clock::now()));
  result.best_validation = state_.best;
  result.best_path = files_.best_model;
  return result;
}

double InbetweenRun::progress() {
  double p = dp_.agree({minutes_now()})[0] / o_.max_minutes;  // rank 0's clock
  if (o_.max_steps > 0) p = std::max(p, static_cast<double>(state_.step) / o_.max_steps);
  return p;
}

// An epoch ends after epoch_steps steps or validate_minutes of wall time.
bool InbetweenRun::train_epoch(EpochSums* sums) {
  const auto epoch_start = Clock::now();
  for (int s = 0; s < epoch_steps_; ++s) {
    const double p = progress();
    if (p >= 1.0) return true;
    // Rank 0's clock decides (data_parallel.h): the epoch's and the checkpoint's age.
    const std::vector<double> age = dp_.agree(
        {seconds_between(epoch_start, Clock::now()), seconds_between(last_checkpoint_, Clock::now())});
    if (age[0] > 60.0 * o_.validate_minutes && sums->count > 0) return false;
    lr_ = training::scheduled_lr(o_.lr, o_.lr_final, p, o_.warmup);
    training::set_learning_rate(*optimizer_, lr_);
    train_step(sums);
    print_progress(*sums);
    if (age[1] > 60.0 * o_.checkpoint_minutes) {
      state_.minutes = minutes_now();
      save_checkpoint();
    }
    if (o_.max_steps > 0 && state_.step >= o_.max_steps) return true;
  }
  return false;
}

void InbetweenRun::train_step(EpochSums* sums) {
  // Per-step seeds: the sample stream does not depend on where a run resumed.
  std::mt19937_64 rng(o_.seed * 1000003ULL + static_cast<uint64_t>(state_.step));
  at::manual_seed(o_.seed * 7919ULL + static_cast<uint64_t>(state_.step));
  // Every rank draws the global batch and trains on its shard.
  std::vector<Sample> samples;
  for (int i = 0; i < o_.batch * dp_.world_size(); ++i) samples.push_back(train_sampler_.draw(rng));
  const auto [first, last] = dp_.shard(0, samples.size());
  double valid_frames = 0;
  for (size_t i = first; i < last; ++i) valid_frames += samples[i].length;
  const auto c0 = Clock::now();
  Batch b = make_batch(data_.train, train_contacts_, samples, first, last, model_->rig(), transitions_);
  const auto c1 = Clock::now();
  StepLosses L = compute_losses(*model_, b, o_.contact_weight);
  const auto c2 = Clock::now();
  optimizer_->zero_grad();
  L.total.backward();
  dp_.average_gradients(model_->parameters(), valid_frames);  // the losses are means over valid frames
  const auto c3 = Clock::now();
  torch::nn::utils::clip_grad_norm_(model_->parameters(), 1.0);
  optimizer_->step();
  if (profile_) {
    std::fprintf(stderr, "  batch %.3f s  forward+loss %.3f s  backward %.3f s  step %.3f s (T = %lld)\n",
                 seconds_between(c0, c1), seconds_between(c1, c2), seconds_between(c2, c3),
                 seconds_between(c3, Clock::now()), static_cast<long long>(b.target.size(1)));
  }
  ++state_.step;
  ++sums->count;
  sums->values[0] += item(L.total);
  for (size_t k = 0; k < L.stages.size() && k < stage_names_.size(); ++k) sums->values[k + 1] += item(L.stages[k]);
  sums->values.back() += item(L.contact);
}

// A progress line after the run's first step and then every 30 s.
void InbetweenRun::print_progress(const EpochSums& sums) {
  const auto now = Clock::now();
  if (!o_.verbose || !dp_.writes() || (state_.step != first_step_ + 1 && seconds_between(last_progress_, now) <= 30.0)) return;
  last_progress_ = now;
  const double sps = (state_.step - first_step_) / seconds_between(run_start_, now);
  std::fprintf(stderr, "  step %lld  epoch %d  %.1f/%.0f min  lr %.2e  loss %.4f", static_cast<long long>(state_.step),
               state_.epoch + 1, minutes_now(), o_.max_minutes, lr_, sums.total());
  for (size_t k = 0; k < stage_names_.size(); ++k) {
    std::fprintf(stderr, "  %s %.4f", stage_names_[k].c_str(), sums.mean(k + 1));
  }
  std::fprintf(stderr, "  contact %.4f  %.2f steps/s\n", sums.contact(), sps);
}

// Per-frame means over the fixed validation set (each rank its share of the
// batches, then the sums over ranks); none (zeros) without validation clips.
Validation InbetweenRun::validate() {
  Validation v;
  v.stages.assign(stage_names_.size(), 0.0);
  if (val_batches_.empty()) return v;
  at::NoGradGuard no_grad;
  model_->train(false);
  double frames = 0;
  for (size_t i = 0; i < val_batches_.size(); ++i) {
    if (!dp_.owns(i)) continue;
    const Batch& b = val_batches_[i];
    StepLosses L = compute_losses(*model_, b, o_.contact_weight);
    const double n = item(b.input.valid.sum());
    v.score += item(L.stages.back()) * n;
    v.rot += item(L.last.rotation) * n;
    v.pos += item(L.last.position) * n;
    v.root += item(L.last.root) * n;
    v.contact += item(L.contact) * n;
    for (size_t k = 0; k < L.stages.size() && k < v.stages.size(); ++k) v.stages[k] += item(L.stages[k]) * n;
    frames += n;
  }
  model_->train(true);
  std::vector<double> all = {v.score, v.rot, v.pos, v.root, v.contact, frames};
  all.insert(all.end(), v.stages.begin(), v.stages.end());
  all = dp_.sum(all);
  v.score = all[0], v.rot = all[1], v.pos = all[2], v.root = all[3], v.contact = all[4];
  std::copy(all.begin() + 6, all.end(), v.stages.begin());
  frames = std::max(all[5], 1.0);
  for (double* x : {&v.score, &v.rot, &v.pos, &v.root, &v.contact}) *x /= frames;
  for (double& x : v.stages) x /= frames;
  return v;
}

// Keeps the best model, writes the checkpoint and the log line (rank 0; the
// training losses are the means over ranks).
void InbetweenRun::end_epoch(const EpochSums& local_sums, const Validation& v) {
  EpochSums sums = local_sums;
  sums.values = dp_.sum(sums.values);
  for (double& x : sums.values) x /= dp_.world_size();
  const double score = val_batches_.empty() ? sums.total() : v.score;  // no validation clips: the training loss decides
  ++state_.epoch;
  state_.minutes = dp_.agree({minutes_now()})[0];
  const bool best = score < state_.best;
  if (best) state_.best = score;
  if (!dp_.writes()) return;
  if (best) save_inbetweener(*model_, files_.best_model);
  save_checkpoint();
  const double sps = (state_.step - first_step_) / std::max(1e-9, seconds_between(run_start_, last_checkpoint_));
  {
    std::ofstream log(files_.log, std::ios::app);
    log.precision(6);
    log << state_.epoch << "," << state_.step << "," << state_.minutes << "," << lr_ << "," << sps << ","
        << sums.total();
    for (size_t k = 0; k < stage_names_.size(); ++k) log << "," << sums.mean(k + 1);
    log << "," << sums.contact() << "," << score << "," << v.rot << "," << v.pos * 100 << "," << v.root * 100;
    for (double x : v.stages) log << "," << x;
    log << "," << v.contact << "," << (best ? 1 : 0) << "\n";
  }
  if (o_.verbose) {
    std::fprintf(stderr,
                 "epoch %d  step %lld  %.1f min  train %.4f | val score %.4f (rot %.4f pos %.2f cm root %.2f cm "
                 "contact %.4f)%s\n",
                 state_.epoch, static_cast<long long>(state_.step), state_.minutes, sums.total(), score, v.rot,
                 v.pos * 100, v.root * 100, v.contact, best ? " (best)" : "");
  }
}

void InbetweenRun::save_checkpoint() {
  if (!dp_.writes()) {
    last_checkpoint_ = Clock::now();
    return;
  }
  save_inbetweener(*model_, files_.last_model);
  training::save_optimizer(*optimizer_, files_.last_optim);
  training::save_trainer_state(files_.last_state, state_);
  last_checkpoint_ = Clock::now();
}

}  // namespace

InbetweenTrainingResult train_inbetweener(const InbetweenTrainingOptions& options) {
  check_options(options);
  set_compute_threads(std::max(1, options.threads));
  fs::create_directories(options.out_dir);
  return InbetweenRun(options).train();
}

}  // namespace mf
