#include "training/prior_trainer.h"

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
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

#include "prior/data/dataset.h"
#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "prior/motion/kinematics_torch.h"
#include "prior/motion/rotations_torch.h"
#include "training/trainer_util.h"
#include "prior/util/threads.h"

namespace mf {

namespace {

namespace fs = std::filesystem;
using at::indexing::Slice;
using training::masked_mean;
using training::padded_slice;

// Per-clip ground-truth quantities that do not depend on where a window
// starts (they are all heading-relative), computed once.
struct ClipTensors {
  at::Tensor features;  // [T, J * 15] raw local-motion features
  at::Tensor gmp_in;    // [T, J * 3 + 6]
  at::Tensor vel;       // [T, 3] root velocity in the heading frame
  at::Tensor height;    // [T, 1]
  at::Tensor contacts;  // [T, F]
};

std::vector<ClipTensors> precompute(const std::vector<Clip>& clips, const RigInfo& rig, double fps) {
  at::NoGradGuard no_grad;
  std::vector<ClipTensors> out;
  out.reserve(clips.size());
  for (const Clip& c : clips) {
    const int n = c.motion.num_frames();
    ClipTensors t;
    if (n >= 2) {
      WindowTensors w = window_tensors(c.motion, 0, n, rig, 0);
      t.features = local_features(w.local_rotations, rig, fps, nullptr).flatten(2).squeeze(0);
      t.gmp_in = gmp_inputs(w.local_rotations, rig).squeeze(0);
      GmpTargets g = gmp_targets(w.local_rotations, w.root_positions, rig, fps);
      t.vel = g.velocity.squeeze(0);
      t.height = g.height.squeeze(0);
      t.contacts = g.contacts.squeeze(0);
    }
    out.push_back(t);
  }
  return out;
}

struct Batch {
  at::Tensor rot;       // [B, W, J, 3, 3] canonical local rotations
  at::Tensor pos;       // [B, W, 3] canonical root positions
  at::Tensor mask;      // [B, W]
  at::Tensor lengths;   // [B] int64
  at::Tensor features;  // [B, W, J * 15]
  at::Tensor gmp_in;    // [B, W, J * 3 + 6]
  at::Tensor vel, height, contacts;
};

Batch make_batch(const std::vector<Clip>& clips, const std::vector<ClipTensors>& pre,
                 const std::vector<Window>& windows, size_t begin, size_t end, const RigInfo& rig, int W) {
  std::vector<at::Tensor> rots, poss, masks, feats, gins, vels, heights, contacts;
  std::vector<int64_t> lengths;
  for (size_t i = begin; i < end; ++i) {
    const Window& w = windows[i];
    WindowTensors t = window_tensors(clips[w.clip].motion, w.start, w.length, rig, 0);
    rots.push_back(padded_slice(t.local_rotations.squeeze(0), 0, w.length, W));
    poss.push_back(padded_slice(t.root_positions.squeeze(0), 0, w.length, W));
    const ClipTensors& p = pre[w.clip];
    feats.push_back(padded_slice(p.features, w.start, w.length, W));
    gins.push_back(padded_slice(p.gmp_in, w.start, w.length, W));
    vels.push_back(padded_slice(p.vel, w.start, w.length, W));
    heights.push_back(padded_slice(p.height, w.start, w.length, W));
    contacts.push_back(padded_slice(p.contacts, w.start, w.length, W));
    at::Tensor m = at::zeros({1, W});
    m.narrow(1, 0, w.length).fill_(1.0);
    masks.push_back(m);
    lengths.push_back(w.length);
  }
  Batch b;
  b.rot = at::cat(rots, 0);
  b.pos = at::cat(poss, 0);
  b.mask = at::cat(masks, 0);
  b.lengths = at::tensor(lengths, at::kLong);
  b.features = at::cat(feats, 0);
  b.gmp_in = at::cat(gins, 0);
  b.vel = at::cat(vels, 0);
  b.height = at::cat(heights, 0);
  b.contacts = at::cat(contacts, 0);
  return b;
}

std::vector<Window> epoch_windows(const std::vector<Clip>& clips, int W, int stride, std::mt19937_64& rng) {
  std::vector<Window> out;
  for (size_t c = 0; c < clips.size(); ++c) {
    const int n = clips[c].motion.num_frames();
    if (n < 2) continue;
    if (n <= W) {
      out.push_back({static_cast<int>(c), 0, n});
      continue;
    }
    const int phase = static_cast<int>(rng() % static_cast<uint64_t>(stride));
    bool any = false;
    for (int s = phase; s + W <= n; s += stride) {
      out.push_back({static_cast<int>(c), s, W});
      any = true;
    }
    if (!any) out.push_back({static_cast<int>(c), n - W, W});
  }
  std::shuffle(out.begin(), out.end(), rng);
  return out;
}

struct Losses {
  at::Tensor rot, root, pos, kl, vel, height, trans, contact;
  at::Tensor total(double beta) const {
    return rot + root + 10.0 * pos + beta * kl + vel + height + trans + 0.5 * contact;
  }
};

// The VAE's losses (rotations, root orientation, positions, KL) into *L.
void compute_vae_losses(const NemfModel& model, const Batch& b, int frames_per_window, int64_t offset,
                        int64_t global, Losses* out) {
  const RigInfo& rig = model.rig();
  const int64_t B = b.rot.size(0), W = b.rot.size(1), J = rig.num_joints();
  Losses& L = *out;
  at::Tensor root6d = torch_rot::matrix_to_sixd(b.rot.select(2, 0));
  NemfLatent z = model.encode_features(b.features, root6d, b.mask);
  at::Tensor zl = z.mu_l, zg = z.mu_g;
  at::Tensor frames, weight, gt;
  if (frames_per_window > 0) {
    const int64_t G = std::max(global, B);
    zl = zl + at::randn({G, zl.size(1)}).narrow(0, offset, B) * at::exp(0.5 * z.logvar_l);
    zg = zg + at::randn({G, zg.size(1)}).narrow(0, offset, B) * at::exp(0.5 * z.logvar_g);
    frames = (at::rand({G, frames_per_window}).narrow(0, offset, B) * b.lengths.unsqueeze(1).to(at::kFloat))
                 .floor()
                 .to(at::kLong);
    frames = at::minimum(frames, (b.lengths - 1).unsqueeze(1));
    gt = b.rot.gather(1, frames.view({B, frames_per_window, 1, 1, 1}).expand({B, frames_per_window, J, 3, 3}));
    weight = at::ones({B, frames_per_window});
  } else {
    frames = at::arange(W, at::kLong).unsqueeze(0).expand({B, W});
    gt = b.rot;
    weight = b.mask;
  }
  at::Tensor dec = model.decode(frames.to(at::kFloat), zl, zg);
  at::Tensor geo = torch_rot::geodesic_angle(dec, gt);  // [B, S, J]
  L.rot = masked_mean(geo.narrow(2, 1, J - 1), weight);
  L.root = masked_mean(geo.narrow(2, 0, 1), weight);
  at::Tensor offsets = offsets_tensor(rig.skeleton);
  at::Tensor origin = at::zeros({B, dec.size(1), 3});
  at::Tensor p_dec = forward_kinematics(rig.skeleton.parents, offsets, dec, origin).positions;
  at::Tensor p_gt = forward_kinematics(rig.skeleton.parents, offsets, gt, origin).positions;
  L.pos = masked_mean((p_dec - p_gt).abs(), weight);
  auto kl = [](const at::Tensor& mu, const at::Tensor& logvar) {
    return (-0.5 * (1 + logvar - mu * mu - at::exp(logvar)).sum(-1)).mean();
  };
  L.kl = kl(z.mu_l, z.logvar_l) + kl(z.mu_g, z.logvar_g);

}

// The GMP's inputs for a batch: the first round(reconstructed * B) windows'
// from the VAE's reconstruction (encode the mean, decode every frame; the
// padding past each window's length stays the captured motion's), the rest
// from the captured motion.
at::Tensor gmp_inputs_for(const NemfModel& model, const Batch& b, double reconstructed) {
  const int64_t B = b.rot.size(0), W = b.rot.size(1);
  const int64_t n = std::min<int64_t>(B, std::llround(reconstructed * static_cast<double>(B)));
  if (n <= 0) return b.gmp_in;
  at::NoGradGuard no_grad;
  at::Tensor root6d = torch_rot::matrix_to_sixd(b.rot.narrow(0, 0, n).select(2, 0));
  NemfLatent z = model.encode_features(b.features.narrow(0, 0, n), root6d, b.mask.narrow(0, 0, n));
  at::Tensor decoded = model.decode(at::arange(W, at::kFloat), z.mu_l, z.mu_g);
  at::Tensor captured = b.gmp_in.narrow(0, 0, n);
  at::Tensor mixed = at::where(b.mask.narrow(0, 0, n).unsqueeze(-1) > 0, gmp_inputs(decoded, model.rig()), captured);
  return n == B ? mixed : at::cat({mixed, b.gmp_in.narrow(0, n, B - n)}, 0);
}

// frames_per_window > 0: the decoder is evaluated on that many random valid
// frames of each window and z is sampled; 0: every frame, z = mu (validation).
// The random numbers are drawn for the whole global batch of `global` windows
// (0 = this batch) and the rows [offset, offset + B) used, so that each
// process of a data-parallel run draws what one process on the global batch
// would (training/data_parallel.h).
// With vae = false only the GMP's losses are computed (the VAE's are zero);
// `reconstructed`: the share of windows whose GMP inputs are the VAE's
// reconstruction (gmp_inputs_for).
Losses compute_losses(const NemfModel& model, const Batch& b, int frames_per_window, int64_t offset = 0,
                      int64_t global = 0, bool vae = true, double reconstructed = 0.0) {
  const RigInfo& rig = model.rig();
  Losses L;
  if (vae) compute_vae_losses(model, b, frames_per_window, offset, global, &L);
  else L.rot = L.root = L.pos = L.kl = at::zeros({});
  GmpOutput g = model.predict_global_from_inputs(gmp_inputs_for(model, b, reconstructed));
  L.vel = masked_mean((g.velocity - b.vel).abs(), b.mask);
  L.height = masked_mean((g.height - b.height).abs(), b.mask);
  at::Tensor start = ground_xz(b.pos.select(1, 0));
  L.trans = masked_mean((model.root_positions(b.rot, g, start) - b.pos).abs(), b.mask);
  if (rig.num_feet() > 0) {
    at::Tensor bce = at::binary_cross_entropy_with_logits(g.contact_logits, b.contacts, {}, {},
                                                          at::Reduction::None);
    L.contact = masked_mean(bce, b.mask);
  } else {
    L.contact = at::zeros({});
  }
  return L;
}

// Normalisation statistics over every training frame.
void compute_stats(NemfModel& model, const std::vector<Clip>& clips, const std::vector<ClipTensors>& pre) {
  at::NoGradGuard no_grad;
  std::vector<at::Tensor> feats, roots, gin, gout;
  for (size_t c = 0; c < clips.size(); ++c) {
    if (!pre[c].features.defined()) continue;
    WindowTensors w = window_tensors(clips[c].motion, 0, clips[c].motion.num_frames(), model.rig(), 0);
    feats.push_back(pre[c].features);
    roots.push_back(torch_rot::matrix_to_sixd(w.local_rotations.select(2, 0)).squeeze(0));
    gin.push_back(pre[c].gmp_in);
    gout.push_back(at::cat({pre[c].vel, pre[c].height}, -1));
  }
  auto mean_std = [](const std::vector<at::Tensor>& parts, at::Tensor& mean, at::Tensor& std) {
    at::Tensor all = at::cat(parts, 0).to(at::kDouble);
    mean = all.mean(0).to(at::kFloat);
    std = all.std(0).clamp_min(1e-3).to(at::kFloat);
  };
  NemfStats& s = model.stats();
  mean_std(feats, s.feature_mean, s.feature_std);
  mean_std(roots, s.root_mean, s.root_std);
  mean_std(gin, s.gmp_in_mean, s.gmp_in_std);
  mean_std(gout, s.gmp_out_mean, s.gmp_out_std);
}

double item(const at::Tensor& t) { return t.item<double>(); }

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double>(b - a).count(); }

void check_options(const PriorTrainingOptions& o) {
  if (o.out_dir.empty()) throw InputError("train: an output directory is required");
  if (o.batch < 1 || o.stride < 1 || o.frames_per_window < 1 || !(o.max_minutes > 0)) {
    throw InputError("train: batch, stride, frames per window and the time budget must be positive");
  }
  std::string problem = o.config.validate();
  if (!problem.empty()) throw InputError("train: " + problem);
  if (o.gmp_only && o.init_from.empty() && !o.resume) {
    throw InputError("train: --gmp-only trains a GMP on a trained prior's VAE: give it with --init");
  }
  if (!(o.gmp_reconstructed >= 0.0 && o.gmp_reconstructed <= 1.0)) {
    throw InputError("train: --gmp-reconstructed is a share of the windows, in [0, 1]");
  }
  if (o.gmp_reconstructed > 0.0 && !o.gmp_only) {
    throw InputError("train: --gmp-reconstructed needs --gmp-only (a frozen VAE to reconstruct with)");
  }
  if (o.config.steering_gmp && !o.gmp_only) {
    throw InputError("train: --steering-gmp needs --gmp-only (the steering GMP is --init's, kept frozen)");
  }
}

bool is_gmp_key(const std::string& key) { return key.rfind("gmp_", 0) == 0 || key == "steering_gmp"; }
bool is_gmp_parameter(const std::string& name) { return name.rfind("gmp.", 0) == 0; }
bool is_steering_parameter(const std::string& name) { return name.rfind("steering_gmp.", 0) == 0; }

// A model of o.config with `init`'s VAE weights and statistics (called only
// when o.config's GMP sizes or steering GMP differ from `init`'s). Its GMP is
// `init`'s when the sizes are the same, else a fresh one; its steering GMP is
// `init`'s steering GMP, or `init`'s GMP when `init` has none. A VAE run
// (no --gmp-only) from a model with a steering GMP drops it and continues
// with it as the GMP: the steering GMP is the one trained with the VAE, the
// default one was fitted afterwards on the VAE's reconstructions.
NemfModel with_new_gmp(const PriorTrainingOptions& o, const NemfModel& init) {
  auto without_gmp = [](const NemfConfig& c) {
    auto map = c.to_map();
    for (auto it = map.begin(); it != map.end();) it = is_gmp_key(it->first) ? map.erase(it) : std::next(it);
    return map;
  };
  if (without_gmp(init.config()) != without_gmp(o.config)) {
    throw InputError("train: --init " + o.init_from + " has other VAE sizes than the options (" +
                     init.config().describe() + "; --gmp-only changes only the --gmp-* sizes)");
  }
  const NemfConfig& c = init.config();
  const bool same_sizes =
      c.gmp_width == o.config.gmp_width && c.gmp_kernel == o.config.gmp_kernel && c.gmp_blocks == o.config.gmp_blocks;
  if (o.config.steering_gmp && !same_sizes) {
    throw InputError("train: --steering-gmp keeps --init " + o.init_from +
                     "'s GMP for steering, so the --gmp-* sizes must be its own (" + c.describe() + ")");
  }
  NemfModel model(o.config, init.rig());
  at::NoGradGuard no_grad;
  std::map<std::string, at::Tensor> source;
  for (const auto& [name, value] : init.named_parameters()) source[name] = value;
  for (const auto& [name, value] : model.named_parameters()) {
    if (is_gmp_parameter(name) && !same_sizes) continue;
    const bool from_gmp = is_steering_parameter(name) && !init.has_steering_gmp();
    const bool from_steering = !o.gmp_only && is_gmp_parameter(name) && init.has_steering_gmp();
    const std::string from = from_gmp ? name.substr(std::string("steering_").size())
                             : from_steering ? "steering_" + name
                                             : name;
    auto it = source.find(from);
    if (it == source.end() || !it->second.sizes().equals(value.sizes())) {
      throw InputError("train: --init " + o.init_from + " has no parameter " + from + " of this model's shape");
    }
    value.copy_(it->second);
  }
  model.stats() = init.stats();
  return model;
}

// A new model of o.config, the checkpoint's when resuming, or o.init_from's (same sizes).
NemfModel load_or_make_model(const PriorTrainingOptions& o, const Dataset& data, const training::RunFiles& files,
                             bool resuming) {
  at::manual_seed(o.seed);
  if (!resuming && o.init_from.empty()) return NemfModel(o.config, training::measure_training_rig(data));
  const std::string what = resuming ? "--resume" : "--init " + o.init_from;
  NemfModel model = load_nemf(resuming ? files.last_model : o.init_from);
  const bool drops_steering = !o.gmp_only && model.has_steering_gmp() && !o.config.steering_gmp;
  if ((o.gmp_only || drops_steering) && !resuming && model.config().to_map() != o.config.to_map())
    model = with_new_gmp(o, model);
  if (model.config().to_map() != o.config.to_map()) {
    throw InputError("train: " + what + " has other sizes than the options (" + model.config().describe() +
                     "; give the same sizes)");
  }
  if (!resuming && !model.rig().skeleton.same_as(data.skeleton)) {
    throw InputError("train: --init " + o.init_from + " is on another skeleton than the training data");
  }
  return model;
}

// Validation windows: every clip cut into whole windows (a shorter clip is one window).
std::vector<Window> validation_windows(const std::vector<Clip>& clips, int W) {
  std::vector<Window> out;
  for (size_t c = 0; c < clips.size(); ++c) {
    const int n = clips[c].motion.num_frames();
    if (n < 2) continue;
    if (n <= W) out.push_back({static_cast<int>(c), 0, n});
    else
      for (int s = 0; s + W <= n; s += W) out.push_back({static_cast<int>(c), s, W});
  }
  return out;
}

// Training-loss sums of one epoch (rot, root, pos, kl, vel, height, trans,
// contact) and the last learning rate and KL weight.
struct EpochSums {
  double values[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int count = 0;
  double lr = 0, beta = 0;
  double mean(int k) const { return values[k] / count; }
};

// Validation per frame: rotation, root orientation (rad), position, translation (m) and the score.
struct Validation {
  double rot = 0, root = 0, pos = 0, trans = 0;
  double score(bool gmp_only) const { return gmp_only ? trans : rot + root + 10.0 * pos; }
};

// One training run: the set-up in the constructor, then train().
class PriorRun {
 public:
  explicit PriorRun(const PriorTrainingOptions& o);
  PriorTrainingResult train();

 private:
  void open_log() const;
  double minutes_now() const { return base_minutes_ + seconds_between(t0_, Clock::now()) / 60.0; }
  // Returns true when the budget (time or steps) is used up.
  bool train_epoch(EpochSums* sums);
  void train_step(const Batch& b, double beta, int64_t offset, int64_t global, EpochSums* sums);
  Validation validate();
  void end_epoch(const EpochSums& sums, const Validation& v);

  const PriorTrainingOptions& o_;
  const Clock::time_point t0_;
  const training::RunFiles files_;
  training::DataParallel dp_;
  Dataset data_;
  bool resuming_ = false;
  const training::RunFiles resume_from_;  // files_, or on ranks > 0 rank 0's checkpoint copied
  NemfModel model_;
  const int W_;
  std::vector<ClipTensors> train_pre_, val_pre_;
  std::vector<Window> val_windows_;
  std::vector<at::Tensor> trained_;  // every parameter, or with gmp_only the GMP's
  torch::optim::Adam optimizer_;
  training::TrainerState state_;
  double base_minutes_ = 0;
  bool profile_ = std::getenv("MF_PROFILE") != nullptr;
};

PriorRun::PriorRun(const PriorTrainingOptions& o)
    : o_(o),
      t0_(Clock::now()),
      files_(o.out_dir),
      dp_(o.distributed),
      data_(training::load_training_data(o.data, o.cache_dir, o.max_train_clips, o.config.fps, o.augmentation,
                                         o.verbose && dp_.writes())),
      resume_from_(dp_.resume_files(files_, o.resume, &resuming_)),
      model_(load_or_make_model(o, data_, resume_from_, resuming_)),
      W_(model_.config().window),
      trained_(o.gmp_only ? model_.gmp_parameters() : model_.parameters()),
      optimizer_(trained_, torch::optim::AdamOptions(o.lr)) {
  const auto p0 = Clock::now();
  train_pre_ = precompute(data_.train, model_.rig(), model_.config().fps);
  val_pre_ = precompute(data_.validation, model_.rig(), model_.config().fps);
  if (o.verbose) std::fprintf(stderr, "train: per-clip features in %.1f s\n", seconds_between(p0, Clock::now()));
  // An --init model keeps its statistics: its weights were trained on them.
  if (!resuming_ && o.init_from.empty()) compute_stats(model_, data_.train, train_pre_);
  model_.set_requires_grad(true);
  if (o.gmp_only)
    for (at::Tensor& p : model_.vae_parameters()) p.requires_grad_(false);
  model_.train(true);
  if (resuming_) {
    torch::load(optimizer_, resume_from_.last_optim);
    state_ = training::load_trainer_state(resume_from_.last_state);
    dp_.check_resumed_world_size(state_);
  } else {
    if (dp_.writes()) open_log();
    // Every rank starts from rank 0's weights and statistics.
    std::vector<at::Tensor> shared = model_.parameters();
    const NemfStats& st = model_.stats();
    shared.insert(shared.end(), {st.feature_mean, st.feature_std, st.root_mean, st.root_std, st.gmp_in_mean,
                                 st.gmp_in_std, st.gmp_out_mean, st.gmp_out_std});
    dp_.broadcast(shared);
  }
  state_.world_size = dp_.world_size();
  base_minutes_ = state_.minutes;
  if (o.verbose && dp_.writes()) {
    std::fprintf(stderr, "train: %zu training clips, %zu validation clips, %d threads; model %s; %lld parameters%s%s\n",
                 data_.train.size(), data_.validation.size(), o.threads, model_.config().describe().c_str(),
                 static_cast<long long>(model_.num_parameters()), resuming_ ? "; resumed" : "",
                 dp_.distributed() ? ("; " + std::to_string(dp_.world_size()) + " processes").c_str() : "");
  }
  val_windows_ = validation_windows(data_.validation, W_);
}

void PriorRun::open_log() const {
  std::ofstream log(files_.log);
  log << "epoch,step,minutes,lr,beta,train_rot,train_root,train_pos,train_kl,train_vel,train_height,train_trans,"
         "train_contact,val_rot_deg,val_root_deg,val_pos_cm,val_trans_cm,val_score\n";
}

PriorTrainingResult PriorRun::train() {
  bool out_of_time = false;
  while (!out_of_time && state_.epoch < o_.max_epochs) {
    EpochSums sums;
    out_of_time = train_epoch(&sums);
    if (sums.count == 0) break;
    end_epoch(sums, validate());
  }
  PriorTrainingResult result;
  result.epochs = state_.epoch;
  result.steps = state_.step;
  result.minutes = state_.minutes;
  result.best_validation = state_.best;
  result.best_path = files_.best_model;
  return result;
}

// One pass over the training windows (a random phase per clip and epoch).
bool PriorRun::train_epoch(EpochSums* sums) {
  std::mt19937_64 rng(o_.seed * 1000003ULL + static_cast<uint64_t>(state_.epoch));
  at::manual_seed(o_.seed * 7919ULL + static_cast<uint64_t>(state_.epoch));
  const std::vector<Window> windows = epoch_windows(data_.train, W_, o_.stride, rng);
  sums->lr = o_.lr;
  sums->beta = o_.kl_weight;
  // A global batch of world_size * batch windows, each rank its shard.
  const size_t global_batch = static_cast<size_t>(o_.batch) * dp_.world_size();
  for (size_t i = 0; i + static_cast<size_t>(dp_.world_size()) <= windows.size(); i += global_batch) {
    const double progress = std::min(1.0, dp_.agree({minutes_now()})[0] / o_.max_minutes);
    if (progress >= 1.0 || (o_.max_steps > 0 && state_.step >= o_.max_steps)) return true;
    sums->lr = training::scheduled_lr(o_.lr, o_.lr_final, progress);
    sums->beta = o_.kl_weight * std::min(1.0, progress / std::max(1e-9, o_.kl_warmup));
    training::set_learning_rate(optimizer_, sums->lr);
    const auto c0 = Clock::now();
    const size_t end = std::min(windows.size(), i + global_batch);
    const auto [first, last] = dp_.shard(i, end);
    Batch b = make_batch(data_.train, train_pre_, windows, first, last, model_.rig(), W_);
    if (profile_) std::fprintf(stderr, "batch %.3f s ", seconds_between(c0, Clock::now()));
    train_step(b, sums->beta, static_cast<int64_t>(first - i), static_cast<int64_t>(end - i), sums);
    if (o_.verbose && dp_.writes() && state_.step % 100 == 0) {
      std::fprintf(stderr, "  step %lld  %.1f min  lr %.2e  rot %.4f pos %.4f kl %.1f trans %.4f\n",
                   static_cast<long long>(state_.step), minutes_now(), sums->lr, sums->mean(0), sums->mean(2),
                   sums->mean(3), sums->mean(6));
    }
  }
  return false;
}

void PriorRun::train_step(const Batch& b, double beta, int64_t offset, int64_t global, EpochSums* sums) {
  const auto c1 = Clock::now();
  Losses L = compute_losses(model_, b, o_.frames_per_window, offset, global, !o_.gmp_only, o_.gmp_reconstructed);
  at::Tensor total = L.total(beta);
  const auto c2 = Clock::now();
  optimizer_.zero_grad();
  total.backward();
  if (profile_) {
    std::fprintf(stderr, "forward %.3f s backward %.3f s\n", seconds_between(c1, c2), seconds_between(c2, Clock::now()));
  }
  const auto c3 = Clock::now();
  dp_.average_gradients(trained_, static_cast<double>(b.rot.size(0)));  // weighted by windows
  if (profile_ && dp_.distributed()) std::fprintf(stderr, "all-reduce %.3f s\n", seconds_between(c3, Clock::now()));
  torch::nn::utils::clip_grad_norm_(trained_, 1.0);
  optimizer_.step();
  ++state_.step;
  const at::Tensor parts[8] = {L.rot, L.root, L.pos, L.kl, L.vel, L.height, L.trans, L.contact};
  for (int k = 0; k < 8; ++k) sums->values[k] += item(parts[k]);
  ++sums->count;
}

// Encode the mean, decode every frame of the fixed validation windows (each
// rank its share of the batches of 64, then the sums over ranks).
Validation PriorRun::validate() {
  at::NoGradGuard no_grad;
  Validation v;
  double frames = 0;
  for (size_t i = 0; i < val_windows_.size(); i += 64) {
    if (!dp_.owns(i / 64)) continue;
    Batch b = make_batch(data_.validation, val_pre_, val_windows_, i, std::min(val_windows_.size(), i + 64),
                         model_.rig(), W_);
    Losses L = compute_losses(model_, b, 0, 0, 0, true, o_.gmp_reconstructed);
    const double n = item(b.mask.sum());
    v.rot += item(L.rot) * n;
    v.root += item(L.root) * n;
    v.pos += item(L.pos) * n;
    v.trans += item(L.trans) * n;
    frames += n;
  }
  const std::vector<double> all = dp_.sum({v.rot, v.root, v.pos, v.trans, frames});
  v = Validation{all[0], all[1], all[2], all[3]};
  frames = all[4];
  for (double* x : {&v.rot, &v.root, &v.pos, &v.trans}) *x /= std::max(frames, 1.0);
  return v;
}

// Keeps the best model, writes the checkpoint and the log line (rank 0; the
// training losses are the means over ranks).
void PriorRun::end_epoch(const EpochSums& local_sums, const Validation& v) {
  EpochSums sums = local_sums;
  const std::vector<double> summed = dp_.sum(std::vector<double>(sums.values, sums.values + 8));
  for (int k = 0; k < 8; ++k) sums.values[k] = summed[k] / dp_.world_size();
  const double score = v.score(o_.gmp_only);
  ++state_.epoch;
  state_.minutes = dp_.agree({minutes_now()})[0];
  const bool best = score < state_.best;
  if (best) state_.best = score;
  if (!dp_.writes()) return;
  if (best) save_nemf(model_, files_.best_model);
  save_nemf(model_, files_.last_model);
  training::save_optimizer(optimizer_, files_.last_optim);
  training::save_trainer_state(files_.last_state, state_);
  {
    std::ofstream log(files_.log, std::ios::app);
    log.precision(6);
    log << state_.epoch << "," << state_.step << "," << state_.minutes << "," << sums.lr << "," << sums.beta;
    for (int k = 0; k < 8; ++k) log << "," << sums.mean(k);
    log << "," << v.rot * 180 / M_PI << "," << v.root * 180 / M_PI << "," << v.pos * 100 << "," << v.trans * 100
        << "," << score << "\n";
  }
  if (o_.verbose) {
    std::fprintf(stderr,
                 "epoch %d  step %lld  %.1f min  train rot %.4f pos %.4f | val rot %.2f deg root %.2f deg pos %.2f cm "
                 "trans %.2f cm score %.4f%s\n",
                 state_.epoch, static_cast<long long>(state_.step), state_.minutes, sums.mean(0), sums.mean(2),
                 v.rot * 180 / M_PI, v.root * 180 / M_PI, v.pos * 100, v.trans * 100, score, best ? " (best)" : "");
  }
}

}  // namespace

PriorTrainingResult train_prior(const PriorTrainingOptions& options) {
  check_options(options);
  set_compute_threads(options.threads);
  fs::create_directories(options.out_dir);
  return PriorRun(options).train();
}

}  // namespace mf
