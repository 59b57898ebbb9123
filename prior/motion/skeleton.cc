#include "prior/motion/skeleton.h"

#include <cmath>
#include <unordered_set>

#include "prior/motion/errors.h"

namespace mf {

int Skeleton::find(const std::string& name) const {
  for (int j = 0; j < num_joints(); ++j)
    if (names[j] == name) return j;
  return -1;
}

void Skeleton::validate() const {
  const size_t n = names.size();
  if (n == 0) throw InputError("skeleton has no joints");
  if (parents.size() != n || offsets.size() != n)
    throw InputError("skeleton sizes disagree: " + std::to_string(n) + " names, " + std::to_string(parents.size()) +
                     " parents, " + std::to_string(offsets.size()) + " offsets");
  if (parents[0] != -1) throw InputError("skeleton joint 0 ('" + names[0] + "') must be the root (parent -1)");
  std::unordered_set<std::string> seen;
  for (size_t j = 0; j < n; ++j) {
    if (names[j].empty()) throw InputError("skeleton joint " + std::to_string(j) + " has an empty name");
    if (!seen.insert(names[j]).second) throw InputError("skeleton joint name '" + names[j] + "' is not unique");
    if (j > 0 && (parents[j] < 0 || parents[j] >= static_cast<int>(j)))
      throw InputError("skeleton joint '" + names[j] + "' has parent " + std::to_string(parents[j]) +
                       "; parents must come before their children and only joint 0 is a root");
    if (!offsets[j].allFinite()) throw InputError("skeleton joint '" + names[j] + "' has a non-finite offset");
  }
}

bool Skeleton::same_as(const Skeleton& other, double tolerance) const {
  if (names != other.names || parents != other.parents || offsets.size() != other.offsets.size()) return false;
  for (size_t j = 1; j < offsets.size(); ++j)
    for (int k = 0; k < 3; ++k)  // written so that NaN compares unequal
      if (!(std::abs(offsets[j][k] - other.offsets[j][k]) <= tolerance)) return false;
  return true;
}

std::vector<std::vector<int>> Skeleton::children() const {
  std::vector<std::vector<int>> result(names.size());
  for (size_t j = 0; j < parents.size() && j < names.size(); ++j)
    if (parents[j] >= 0 && parents[j] < static_cast<int>(names.size()))
      result[parents[j]].push_back(static_cast<int>(j));
  return result;
}

}  // namespace mf
