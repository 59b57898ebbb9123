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

// frames_per_window > 0: the decoder is evaluated on that many random valid
// frames of each window and z is sampled; 0: every frame, z = mu (validation).
Losses compute_losses(const NemfModel& model, const Batch& b, int frames_per_window) {
  const RigInfo& rig = model.rig();
  const int64_t B = b.rot.size(0), W = b.rot.size(1), J = rig.num_joints();
  const double fps = model.config().fps;
  Losses L;
  at::Tensor root6d = torch_rot::matrix_to_sixd(b.rot.select(2, 0));
  NemfLatent z = model.encode_features(b.features, root6d, b.mask);
  at::Tensor zl = z.mu_l, zg = z.mu_g;
  at::Tensor frames, weight, gt;
  if (frames_per_window > 0) {
    zl = zl + at::randn_like(zl) * at::exp(0.5 * z.logvar_l);
    zg = zg + at::randn_like(zg) * at::exp(0.5 * z.logvar_g);
    frames = (at::rand({B, frames_per_window}) * b.lengths.unsqueeze(1).to(at::kFloat)).floor().to(at::kLong);
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

  GmpOutput g = model.predict_global_from_inputs(b.gmp_in);
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

}  // namespace

PriorTrainingResult train_prior(const PriorTrainingOptions& o) {
  if (o.out_dir.empty()) throw InputError("train: an output directory is required");
  if (o.batch < 1 || o.stride < 1 || o.frames_per_window < 1 || !(o.max_minutes > 0)) {
    throw InputError("train: batch, stride, frames per window and the time budget must be positive");
  }
  std::string problem = o.config.validate();
  if (!problem.empty()) throw InputError("train: " + problem);
  mf::set_compute_threads(o.threads);
  fs::create_directories(o.out_dir);
  const auto t0 = std::chrono::steady_clock::now();

  Dataset data = training::load_training_data(o.data, o.cache_dir, o.max_train_clips, o.config.fps, o.verbose);
  std::vector<Clip>& train = data.train;
  const std::string last_model = o.out_dir + "/last.mfm", last_optim = o.out_dir + "/last.optim",
                    last_state = o.out_dir + "/last.state", best_model = o.out_dir + "/best.mfm",
                    log_path = o.out_dir + "/log.csv";
  const bool resuming = o.resume && fs::exists(last_model) && fs::exists(last_state) && fs::exists(last_optim);
  at::manual_seed(o.seed);
  NemfModel model = resuming ? load_nemf(last_model) : NemfModel(o.config, training::measure_training_rig(data));
  if (resuming && model.config().to_map() != o.config.to_map()) {
    throw InputError("train: --resume with different sizes than the checkpoint (" + model.config().describe() + ")");
  }
  const auto p0 = std::chrono::steady_clock::now();
  std::vector<ClipTensors> train_pre = precompute(train, model.rig(), model.config().fps);
  std::vector<ClipTensors> val_pre = precompute(data.validation, model.rig(), model.config().fps);
  if (o.verbose) {
    std::fprintf(stderr, "train: per-clip features in %.1f s\n",
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - p0).count());
  }
  if (!resuming) compute_stats(model, train, train_pre);
  model.set_requires_grad(true);
  model.train(true);

  torch::optim::Adam optimizer(model.parameters(), torch::optim::AdamOptions(o.lr));
  training::TrainerState state;
  if (resuming) {
    torch::load(optimizer, last_optim);
    state = training::load_trainer_state(last_state);
  }
  if (!resuming) {
    std::ofstream log(log_path);
    log << "epoch,step,minutes,lr,beta,train_rot,train_root,train_pos,train_kl,train_vel,train_height,train_trans,"
           "train_contact,val_rot_deg,val_root_deg,val_pos_cm,val_trans_cm,val_score\n";
  }
  const double base_minutes = state.minutes;
  auto minutes_now = [&] {
    return base_minutes + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / 60.0;
  };
  if (o.verbose) {
    std::fprintf(stderr, "train: %zu training clips, %zu validation clips, %d threads; model %s; %lld parameters%s\n",
                 train.size(), data.validation.size(), o.threads, model.config().describe().c_str(),
                 static_cast<long long>(model.num_parameters()), resuming ? "; resumed" : "");
  }

  // Fixed validation windows.
  std::vector<Window> val_windows;
  const int W = model.config().window;
  for (size_t c = 0; c < data.validation.size(); ++c) {
    const int n = data.validation[c].motion.num_frames();
    if (n < 2) continue;
    if (n <= W) val_windows.push_back({static_cast<int>(c), 0, n});
    else
      for (int s = 0; s + W <= n; s += W) val_windows.push_back({static_cast<int>(c), s, W});
  }

  PriorTrainingResult result;
  bool out_of_time = false;
  while (!out_of_time && state.epoch < o.max_epochs) {
    std::mt19937_64 rng(o.seed * 1000003ULL + static_cast<uint64_t>(state.epoch));
    at::manual_seed(o.seed * 7919ULL + static_cast<uint64_t>(state.epoch));
    std::vector<Window> windows = epoch_windows(train, W, o.stride, rng);
    double sums[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    int count = 0;
    double lr = o.lr, beta = o.kl_weight;
    for (size_t i = 0; i < windows.size(); i += o.batch) {
      double progress = std::min(1.0, minutes_now() / o.max_minutes);
      if (progress >= 1.0 || (o.max_steps > 0 && state.step >= o.max_steps)) {
        out_of_time = true;
        break;
      }
      lr = training::scheduled_lr(o.lr, o.lr_final, progress);
      beta = o.kl_weight * std::min(1.0, progress / std::max(1e-9, o.kl_warmup));
      training::set_learning_rate(optimizer, lr);
      auto c0 = std::chrono::steady_clock::now();
      Batch b = make_batch(train, train_pre, windows, i, std::min(windows.size(), i + o.batch), model.rig(), W);
      auto c1 = std::chrono::steady_clock::now();
      Losses L = compute_losses(model, b, o.frames_per_window);
      at::Tensor total = L.total(beta);
      auto c2 = std::chrono::steady_clock::now();
      optimizer.zero_grad();
      total.backward();
      auto c3 = std::chrono::steady_clock::now();
      if (std::getenv("MF_PROFILE")) {
        std::fprintf(stderr, "batch %.3f s forward %.3f s backward %.3f s\n", std::chrono::duration<double>(c1 - c0).count(),
                     std::chrono::duration<double>(c2 - c1).count(), std::chrono::duration<double>(c3 - c2).count());
      }
      torch::nn::utils::clip_grad_norm_(model.parameters(), 1.0);
      optimizer.step();
      ++state.step;
      const at::Tensor parts[8] = {L.rot, L.root, L.pos, L.kl, L.vel, L.height, L.trans, L.contact};
      for (int k = 0; k < 8; ++k) sums[k] += item(parts[k]);
      ++count;
      if (o.verbose && state.step % 100 == 0) {
        std::fprintf(stderr, "  step %lld  %.1f min  lr %.2e  rot %.4f pos %.4f kl %.1f trans %.4f\n",
                     static_cast<long long>(state.step), minutes_now(), lr, sums[0] / count, sums[2] / count,
                     sums[3] / count, sums[6] / count);
      }
    }
    if (count == 0) break;
    // Validation.
    double v[5] = {0, 0, 0, 0, 0};
    double vw = 0;
    {
      at::NoGradGuard no_grad;
      for (size_t i = 0; i < val_windows.size(); i += 64) {
        Batch b = make_batch(data.validation, val_pre, val_windows, i, std::min(val_windows.size(), i + 64), model.rig(), W);
        Losses L = compute_losses(model, b, 0);
        double n = item(b.mask.sum());
        v[0] += item(L.rot) * n;
        v[1] += item(L.root) * n;
        v[2] += item(L.pos) * n;
        v[3] += item(L.trans) * n;
        vw += n;
      }
    }
    for (int k = 0; k < 4; ++k) v[k] /= std::max(vw, 1.0);
    const double score = v[0] + v[1] + 10.0 * v[2];
    ++state.epoch;
    state.minutes = minutes_now();
    const bool best = score < state.best;
    if (best) {
      state.best = score;
      save_nemf(model, best_model);
    }
    save_nemf(model, last_model);
    torch::save(optimizer, last_optim);
    training::save_trainer_state(last_state, state);
    {
      std::ofstream log(log_path, std::ios::app);
      log.precision(6);
      log << state.epoch << "," << state.step << "," << state.minutes << "," << lr << "," << beta;
      for (int k = 0; k < 8; ++k) log << "," << sums[k] / count;
      log << "," << v[0] * 180 / M_PI << "," << v[1] * 180 / M_PI << "," << v[2] * 100 << "," << v[3] * 100 << ","
          << score << "\n";
    }
    if (o.verbose) {
      std::fprintf(stderr,
                   "epoch %d  step %lld  %.1f min  train rot %.4f pos %.4f | val rot %.2f deg root %.2f deg pos %.2f cm "
                   "trans %.2f cm score %.4f%s\n",
                   state.epoch, static_cast<long long>(state.step), state.minutes, sums[0] / count, sums[2] / count,
                   v[0] * 180 / M_PI, v[1] * 180 / M_PI, v[2] * 100, v[3] * 100, score, best ? " (best)" : "");
    }
  }
  result.epochs = state.epoch;
  result.steps = state.step;
  result.minutes = state.minutes;
  result.best_validation = state.best;
  result.best_path = best_model;
  return result;
}

}  // namespace mf
