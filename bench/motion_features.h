// NeMF's set-level metrics of generated motion (He et al. 2022, its
// evaluation code): the Frechet distance between the feature statistics of
// generated and real windows ("FID") and the diversity of the generated ones,
// with the features of a separately trained motion encoder.
//
// The feature extractor is a NeMF prior trained here for this purpose only
// (models/evaluation/motion-features.mfm; docs/BENCHMARKS.md, "Distribution
// metrics", with the command that trained it): its encoders' means (mu of z_l,
// then mu of z_g) of a window on the model's rig are the window's features, as
// NeMF takes the encoders of a prior trained apart from the evaluated one.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "prior/model/nemf.h"
#include "prior/motion/motion.h"

namespace mf::bench {

class MotionFeatures {
 public:
  /// Loads the extractor (a NeMF model file); throws mf::InputError when the
  /// file cannot be read.
  explicit MotionFeatures(const std::string& model_path);

  /// The features of `window` (2 to the extractor's window length frames, on
  /// its skeleton, at its frame rate): [z_l + z_g] encoder means. Throws
  /// mf::InputError for another skeleton or length.
  Eigen::VectorXd features(const Motion& window) const;

  /// The extractor's window length (frames).
  int window() const;

 private:
  NemfModel model_;
};

/// The Frechet distance between Gaussians fitted to the rows of `a` and of
/// `b` (samples x features): |mu_a - mu_b|^2 + tr(C_a + C_b - 2 (C_a C_b)^(1/2)),
/// the trace of the square root taken as that of (C_a^(1/2) C_b C_a^(1/2))^(1/2)
/// (symmetric; negative eigenvalues from rounding count as 0). Covariances
/// are the unbiased ones (NeMF's numpy.cov); at least 0. Throws mf::InputError unless both
/// have at least two rows and the same columns.
double frechet_distance(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b);

/// NeMF's diversity: the rows shuffled (a generator seeded with `seed`), the
/// first half paired with the second, the mean Euclidean distance of the
/// pairs. Throws mf::InputError with fewer than two rows.
double feature_diversity(const Eigen::MatrixXd& features, uint64_t seed = 0);

/// Features of real and generated windows gathered per named set (one table
/// row: for example "gap 30 / nemf-detail"), in the order first seen.
class FeatureSets {
 public:
  void add(const std::string& set, const Eigen::VectorXd& truth, const Eigen::VectorXd& generated);
  /// One side only (sets whose real and generated windows are not paired,
  /// such as the prior's samples).
  void add_truth(const std::string& set, const Eigen::VectorXd& truth);
  void add_generated(const std::string& set, const Eigen::VectorXd& generated);

  /// A markdown table: per set the windows (generated / real), the Frechet distance of the
  /// generated windows' features to the real ones', the diversity of the
  /// generated and of the real windows. Sets with fewer than two windows show
  /// "-".
  std::string table() const;

 private:
  struct Set {
    std::vector<Eigen::VectorXd> truth, generated;
  };
  Set& at(const std::string& set);
  std::vector<std::string> order_;
  std::map<std::string, Set> sets_;
};

/// Rows = the vectors (all of one size).
Eigen::MatrixXd stack_rows(const std::vector<Eigen::VectorXd>& rows);

}  // namespace mf::bench
