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
#include <random>

#include "prior/inbetween/inbetweener.h"
#include "prior/motion/errors.h"
#include "training/trainer_util.h"
#include "prior/util/threads.h"

namespace mf {

namespace {

namespace fs = std::filesystem;

struct Sample {
  int clip = 0;
  int start = 0;
  int length = 0;
  std::vector<float> known;  // [length, J + 1]
};

struct Batch {
  InbetweenBatch input;
  at::Tensor target;    // [B, T, D] raw pose features (padding repeats the last frame)
  at::Tensor contacts;  // [B, T, F]
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
  Sampler(const std::vector<Clip>& clips, const RigInfo& rig, int window, int min_length)
      : clips_(clips), J_(rig.num_joints()), window_(window), min_length_(std::min(min_length, window)),
        legs_(leg_joints(rig)) {
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
    const int L = std::uniform_int_distribution<int>(min_length_, window_)(rng);
    s.length = std::min(L, n);
    s.start = n > s.length ? std::uniform_int_distribution<int>(0, n - s.length)(rng) : 0;
    s.known = known_pattern(s.length, rng);
    return s;
  }

 private:
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

Batch make_batch(const std::vector<Clip>& clips, const std::vector<at::Tensor>& contacts,
                 const std::vector<Sample>& samples, size_t begin, size_t end, const RigInfo& rig) {
  at::NoGradGuard no_grad;
  const int J = rig.num_joints();
  int T = 0;
  for (size_t i = begin; i < end; ++i) T = std::max(T, samples[i].length);
  std::vector<at::Tensor> targets, knowns, valids, feet;
  for (size_t i = begin; i < end; ++i) {
    const Sample& s = samples[i];
    WindowTensors w = window_tensors(clips[s.clip].motion, s.start, s.length, rig, 0);
    at::Tensor pose = pose_features(w.local_rotations, w.root_positions).squeeze(0);  // [n, D]
    targets.push_back(training::padded_slice(pose, 0, s.length, T));
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
  return b;
}

struct StepLosses {
  std::vector<at::Tensor> stages;  // inbetween_pose_loss per stage
  InbetweenLossParts last;         // parts of the last stage
  at::Tensor contact;              // undefined without contacts
  at::Tensor total;
};

StepLosses compute_losses(const InbetweenModel& model, const Batch& b, double contact_weight) {
  InbetweenOutput out = model.forward(b.input);
  if (out.stages.empty()) throw std::runtime_error("in-betweener returned no stage");
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

void save_checkpoint(const InbetweenModel& model, torch::optim::Adam& optimizer, const training::TrainerState& state,
                     const std::string& dir) {
  save_inbetweener(model, dir + "/last.mfm");
  torch::save(optimizer, dir + "/last.optim.tmp");
  fs::rename(dir + "/last.optim.tmp", dir + "/last.optim");
  training::save_trainer_state(dir + "/last.state", state);
}

}  // namespace

InbetweenTrainingResult train_inbetweener(const InbetweenTrainingOptions& o) {
  if (o.out_dir.empty()) throw InputError("train: an output directory is required");
  if (o.batch < 1 || o.min_length < 2 || !(o.max_minutes > 0) || !(o.lr > 0) || o.validation_windows < 0 ||
      !(o.warmup >= 0 && o.warmup < 1)) {
    throw InputError(
        "train: batch, time budget and learning rate must be positive, min length at least 2, warm-up in [0, 1)");
  }
  mf::set_compute_threads(std::max(1, o.threads));
  fs::create_directories(o.out_dir);
  const auto t0 = std::chrono::steady_clock::now();

  Dataset data = training::load_training_data(o.data, o.cache_dir, o.max_train_clips, 0.0, o.verbose);
  const std::string last_model = o.out_dir + "/last.mfm", last_optim = o.out_dir + "/last.optim",
                    last_state = o.out_dir + "/last.state", best_model = o.out_dir + "/best.mfm",
                    log_path = o.out_dir + "/log.csv";
  const bool resuming = o.resume && fs::exists(last_model) && fs::exists(last_state) && fs::exists(last_optim);
  at::manual_seed(o.seed);
  std::unique_ptr<InbetweenModel> model =
      resuming ? load_inbetweener(last_model)
               : make_inbetweener(o.kind, o.hyperparameters, training::measure_training_rig(data));
  if (resuming) {
    if (model->kind() != o.kind) {
      throw InputError("train: --resume: the checkpoint holds a '" + model->kind() + "' model, not '" + o.kind + "'");
    }
    auto hp = model->hyperparameters();
    for (const auto& [k, v] : o.hyperparameters) {
      auto it = hp.find(k);
      if (it == hp.end() || it->second != v) {
        throw InputError("train: --resume with other hyperparameters than the checkpoint (" + model->describe() + ")");
      }
    }
  }
  for (const Clip& c : data.train) {
    if (std::abs(c.motion.fps - model->fps()) > 1e-3) {
      throw InputError("train: clip " + c.name + " is at " + std::to_string(c.motion.fps) + " fps, the model at " +
                       std::to_string(model->fps()) + " fps");
    }
  }
  const RigInfo& rig = model->rig();
  if (!rig.skeleton.same_as(data.skeleton)) throw InputError("train: the checkpoint's skeleton differs from the data's");
  const int W = model->window();
  Sampler train_sampler(data.train, rig, W, o.min_length);
  if (train_sampler.empty()) throw InputError("train: no training clip has 2 frames or more");
  Sampler val_sampler(data.validation, rig, W, o.min_length);
  std::vector<at::Tensor> train_contacts = clip_contacts(data.train, rig, model->fps());
  std::vector<at::Tensor> val_contacts = clip_contacts(data.validation, rig, model->fps());

  if (!resuming) {
    // Pose statistics over sampled training windows (root positions depend on
    // the canonical frame, so measure them as the model will see them).
    at::NoGradGuard no_grad;
    std::mt19937_64 rng(o.seed * 31 + 7);
    std::vector<Sample> samples;
    const int n = std::max(64, std::min(2000, static_cast<int>(train_sampler.total_frames() / 32)));
    for (int i = 0; i < n; ++i) samples.push_back(train_sampler.draw(rng));
    std::vector<at::Tensor> frames;
    for (size_t i = 0; i < samples.size(); i += 64) {
      Batch b = make_batch(data.train, train_contacts, samples, i, std::min(samples.size(), i + 64), rig);
      frames.push_back(b.target.flatten(0, 1).index({b.input.valid.flatten() > 0.5}));
    }
    at::Tensor all = at::cat(frames, 0).to(at::kDouble);
    model->stats().pose_mean = all.mean(0).to(at::kFloat);
    model->stats().pose_std = all.std(0).clamp_min(1e-3).to(at::kFloat);
  }

  // Fixed validation set.
  std::vector<Batch> val_batches;
  if (!val_sampler.empty()) {
    std::mt19937_64 rng(0x5eed5eedULL);
    std::vector<Sample> samples;
    for (int i = 0; i < o.validation_windows; ++i) samples.push_back(val_sampler.draw(rng));
    for (size_t i = 0; i < samples.size(); i += 64) {
      val_batches.push_back(make_batch(data.validation, val_contacts, samples, i, std::min(samples.size(), i + 64), rig));
    }
  }

  model->set_requires_grad(true);
  model->train(true);
  torch::optim::Adam optimizer(model->parameters(), torch::optim::AdamOptions(o.lr));
  training::TrainerState state;
  if (resuming) {
    torch::load(optimizer, last_optim);
    state = training::load_trainer_state(last_state);
  }
  const std::vector<std::string> stage_names = model->stage_names();
  if (!resuming || !fs::exists(log_path)) {
    std::ofstream log(log_path);
    log << "epoch,step,minutes,lr,steps_per_s,train_loss";
    for (const auto& s : stage_names) log << ",train_" << s;
    log << ",train_contact,val_score,val_rot,val_pos_cm,val_root_cm";
    for (const auto& s : stage_names) log << ",val_" << s;
    log << ",val_contact,best\n";
  }
  const double base_minutes = state.minutes;
  auto minutes_now = [&] {
    return base_minutes + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / 60.0;
  };
  const double mean_length = 0.5 * (std::min(o.min_length, W) + W);
  const int epoch_steps = o.epoch_steps > 0 ? o.epoch_steps
                                            : std::max(1, static_cast<int>(train_sampler.total_frames() /
                                                                           (mean_length * o.batch)));
  if (o.verbose) {
    std::fprintf(stderr,
                 "train %s: %zu training clips, %zu validation clips (%zu validation windows), %d threads; %s; %lld "
                 "parameters; epoch = %d steps%s\n",
                 model->kind().c_str(), data.train.size(), data.validation.size(),
                 static_cast<size_t>(o.validation_windows), std::max(1, o.threads), model->describe().c_str(),
                 static_cast<long long>(model->num_parameters()), epoch_steps, resuming ? "; resumed" : "");
  }

  const bool profile = std::getenv("MF_PROFILE") != nullptr;
  if (o.verbose) {
    std::fprintf(stderr, "train: set-up (data, statistics, validation set) in %.1f s\n",
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  const int64_t first_step = state.step;
  const auto run_start = std::chrono::steady_clock::now();
  auto last_checkpoint = run_start, last_progress = run_start;
  InbetweenTrainingResult result;
  bool done = false;
  double lr = o.lr;
  while (!done && state.epoch < o.max_epochs) {
    const auto epoch_start = std::chrono::steady_clock::now();
    std::vector<double> sums(stage_names.size() + 2, 0.0);  // total, stages..., contact
    int count = 0;
    for (int s = 0; s < epoch_steps; ++s) {
      double progress = minutes_now() / o.max_minutes;
      if (o.max_steps > 0) progress = std::max(progress, static_cast<double>(state.step) / o.max_steps);
      if (progress >= 1.0) {
        done = true;
        break;
      }
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - epoch_start).count() >
          60.0 * o.validate_minutes && count > 0) {
        break;
      }
      lr = training::scheduled_lr(o.lr, o.lr_final, progress, o.warmup);
      training::set_learning_rate(optimizer, lr);
      // Per-step seeds: the sample stream does not depend on where a run resumed.
      std::mt19937_64 rng(o.seed * 1000003ULL + static_cast<uint64_t>(state.step));
      at::manual_seed(o.seed * 7919ULL + static_cast<uint64_t>(state.step));
      std::vector<Sample> samples;
      for (int i = 0; i < o.batch; ++i) samples.push_back(train_sampler.draw(rng));
      const auto c0 = std::chrono::steady_clock::now();
      Batch b = make_batch(data.train, train_contacts, samples, 0, samples.size(), rig);
      const auto c1 = std::chrono::steady_clock::now();
      StepLosses L = compute_losses(*model, b, o.contact_weight);
      const auto c2 = std::chrono::steady_clock::now();
      optimizer.zero_grad();
      L.total.backward();
      const auto c3 = std::chrono::steady_clock::now();
      torch::nn::utils::clip_grad_norm_(model->parameters(), 1.0);
      optimizer.step();
      if (profile) {
        std::fprintf(stderr, "  batch %.3f s  forward+loss %.3f s  backward %.3f s  step %.3f s (T = %lld)\n",
                     std::chrono::duration<double>(c1 - c0).count(), std::chrono::duration<double>(c2 - c1).count(),
                     std::chrono::duration<double>(c3 - c2).count(),
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - c3).count(),
                     static_cast<long long>(b.target.size(1)));
      }
      ++state.step;
      ++count;
      sums[0] += item(L.total);
      for (size_t k = 0; k < L.stages.size() && k < stage_names.size(); ++k) sums[k + 1] += item(L.stages[k]);
      sums.back() += item(L.contact);
      const auto now = std::chrono::steady_clock::now();
      if (o.verbose && (state.step == first_step + 1 ||
                        std::chrono::duration<double>(now - last_progress).count() > 30.0)) {
        last_progress = now;
        const double sps = (state.step - first_step) / std::chrono::duration<double>(now - run_start).count();
        std::fprintf(stderr, "  step %lld  epoch %d  %.1f/%.0f min  lr %.2e  loss %.4f", static_cast<long long>(state.step),
                     state.epoch + 1, minutes_now(), o.max_minutes, lr, sums[0] / count);
        for (size_t k = 0; k < stage_names.size(); ++k) {
          std::fprintf(stderr, "  %s %.4f", stage_names[k].c_str(), sums[k + 1] / count);
        }
        std::fprintf(stderr, "  contact %.4f  %.2f steps/s\n", sums.back() / count, sps);
      }
      if (std::chrono::duration<double>(now - last_checkpoint).count() > 60.0 * o.checkpoint_minutes) {
        state.minutes = minutes_now();
        save_checkpoint(*model, optimizer, state, o.out_dir);
        last_checkpoint = std::chrono::steady_clock::now();
      }
      if (o.max_steps > 0 && state.step >= o.max_steps) {
        done = true;
        break;
      }
    }
    if (count == 0) break;

    // Validation.
    double score = 0, rot = 0, pos = 0, root = 0, contact = 0, frames = 0;
    std::vector<double> stage_val(stage_names.size(), 0.0);
    if (!val_batches.empty()) {
      at::NoGradGuard no_grad;
      model->train(false);
      for (const Batch& b : val_batches) {
        StepLosses L = compute_losses(*model, b, o.contact_weight);
        const double n = item(b.input.valid.sum());
        score += item(L.stages.back()) * n;
        rot += item(L.last.rotation) * n;
        pos += item(L.last.position) * n;
        root += item(L.last.root) * n;
        contact += item(L.contact) * n;
        for (size_t k = 0; k < L.stages.size() && k < stage_val.size(); ++k) stage_val[k] += item(L.stages[k]) * n;
        frames += n;
      }
      model->train(true);
      frames = std::max(frames, 1.0);
      score /= frames;
      rot /= frames;
      pos /= frames;
      root /= frames;
      contact /= frames;
      for (double& v : stage_val) v /= frames;
    } else {
      score = sums[0] / count;  // no validation clips: the training loss decides
    }
    ++state.epoch;
    state.minutes = minutes_now();
    const bool best = score < state.best;
    if (best) {
      state.best = score;
      save_inbetweener(*model, best_model);
    }
    save_checkpoint(*model, optimizer, state, o.out_dir);
    last_checkpoint = std::chrono::steady_clock::now();
    const double sps =
        (state.step - first_step) / std::max(1e-9, std::chrono::duration<double>(last_checkpoint - run_start).count());
    {
      std::ofstream log(log_path, std::ios::app);
      log.precision(6);
      log << state.epoch << "," << state.step << "," << state.minutes << "," << lr << "," << sps << ","
          << sums[0] / count;
      for (size_t k = 0; k < stage_names.size(); ++k) log << "," << sums[k + 1] / count;
      log << "," << sums.back() / count << "," << score << "," << rot << "," << pos * 100 << "," << root * 100;
      for (double v : stage_val) log << "," << v;
      log << "," << contact << "," << (best ? 1 : 0) << "\n";
    }
    if (o.verbose) {
      std::fprintf(stderr,
                   "epoch %d  step %lld  %.1f min  train %.4f | val score %.4f (rot %.4f pos %.2f cm root %.2f cm "
                   "contact %.4f)%s\n",
                   state.epoch, static_cast<long long>(state.step), state.minutes, sums[0] / count, score, rot,
                   pos * 100, root * 100, contact, best ? " (best)" : "");
    }
  }
  result.epochs = state.epoch;
  result.steps = state.step;
  result.minutes = state.minutes;
  result.steps_per_second =
      (state.step - first_step) /
      std::max(1e-9, std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count());
  result.best_validation = state.best;
  result.best_path = best_model;
  return result;
}

}  // namespace mf
