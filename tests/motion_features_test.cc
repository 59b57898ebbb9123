#include "bench/motion_features.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "prior/model/model_file.h"
#include "prior/motion/errors.h"
#include "tests/test_util.h"

namespace mf::bench {
namespace {

Eigen::MatrixXd random_rows(int rows, int cols, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::MatrixXd m(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) m(i, j) = normal(rng) * (1.0 + j);
  return m;
}

TEST(MotionFeatures, FrechetDistanceOfASetToItselfIsZero) {
  const Eigen::MatrixXd a = random_rows(50, 6, 1);
  EXPECT_NEAR(frechet_distance(a, a), 0.0, 1e-9);
}

TEST(MotionFeatures, FrechetDistanceOfAShiftedSetIsTheSquaredShift) {
  // Same covariance: only the means differ.
  const Eigen::MatrixXd a = random_rows(40, 5, 2);
  Eigen::RowVectorXd shift(5);
  shift << 1.0, -2.0, 0.5, 0.0, 3.0;
  const Eigen::MatrixXd b = a.rowwise() + shift;
  EXPECT_NEAR(frechet_distance(a, b), shift.squaredNorm(), 1e-8);
}

TEST(MotionFeatures, FrechetDistanceOfAScaledSetFollowsTheFormula) {
  // b = 2 a about the mean: C_b = 4 C_a, so tr(C_a + C_b - 2 (C_a C_b)^(1/2)) = tr(C_a).
  const Eigen::MatrixXd a = random_rows(60, 4, 3);
  const Eigen::RowVectorXd mean = a.colwise().mean();
  const Eigen::MatrixXd centred = a.rowwise() - mean;
  const Eigen::MatrixXd b = (2.0 * centred).rowwise() + mean;
  const double trace = (centred.transpose() * centred).trace() / (a.rows() - 1);
  EXPECT_NEAR(frechet_distance(a, b), trace, 1e-8 * trace);
  // Fewer rows than features (rank-deficient covariances, as with 100
  // windows of 160 features) stay finite and non-negative.
  const double d = frechet_distance(random_rows(5, 12, 4), random_rows(7, 12, 5));
  EXPECT_TRUE(std::isfinite(d));
  EXPECT_GE(d, 0.0);
  EXPECT_THROW(frechet_distance(random_rows(1, 3, 6), random_rows(4, 3, 7)), InputError);
  EXPECT_THROW(frechet_distance(random_rows(4, 3, 6), random_rows(4, 2, 7)), InputError);
}

TEST(MotionFeatures, DiversityIsTheMeanDistanceOfRandomPairs) {
  // Points at the corners of a regular simplex: every pair is sqrt(2) apart,
  // whichever way they are shuffled.
  const Eigen::MatrixXd simplex = Eigen::MatrixXd::Identity(6, 6);
  EXPECT_NEAR(feature_diversity(simplex, 1), std::sqrt(2.0), 1e-12);
  EXPECT_NEAR(feature_diversity(simplex, 99), std::sqrt(2.0), 1e-12);
  // Identical rows have no diversity; a wider spread has more.
  EXPECT_EQ(feature_diversity(Eigen::MatrixXd::Ones(8, 3)), 0.0);
  const Eigen::MatrixXd a = random_rows(50, 4, 8);
  EXPECT_NEAR(feature_diversity(3.0 * a, 5), 3.0 * feature_diversity(a, 5), 1e-9);
  EXPECT_THROW(feature_diversity(random_rows(1, 3, 9)), InputError);
}

TEST(MotionFeatures, TheExtractorsEncoderMeansAreTheFeatures) {
  const std::string path = test::scratch_dir("motion_features") + "/extractor.mfm";
  const NemfModel model = test::tiny_prior(3);
  save_nemf(model, path);
  const MotionFeatures extractor(path);
  EXPECT_EQ(extractor.window(), model.config().window);
  const Motion a = test::random_motion(model.rig().skeleton, 20, 30.0, 1);
  const Motion b = test::random_motion(model.rig().skeleton, 20, 30.0, 2);
  const Eigen::VectorXd fa = extractor.features(a);
  ASSERT_EQ(fa.size(), model.config().zl + model.config().zg);
  EXPECT_TRUE(fa.isApprox(extractor.features(a)));
  EXPECT_GT((fa - extractor.features(b)).norm(), 1e-6);
  EXPECT_THROW(extractor.features(a.slice(0, 1)), InputError);
  EXPECT_THROW(extractor.features(test::random_motion(model.rig().skeleton, model.config().window + 1, 30.0, 3)),
               InputError);
  EXPECT_THROW(MotionFeatures("/nonexistent/extractor.mfm"), InputError);

  FeatureSets sets;
  sets.add("gap 30 / interp", fa, fa);
  sets.add("gap 30 / interp", extractor.features(b), extractor.features(b));
  sets.add_generated("prior samples", fa);
  const std::string table = sets.table();
  EXPECT_NE(table.find("| gap 30 / interp | 2 | 0.0000 |"), std::string::npos) << table;
  EXPECT_NE(table.find("| prior samples | 1 / 0 | - | - | - |"), std::string::npos) << table;
}

}  // namespace
}  // namespace mf::bench
