#pragma once
// The guide author's posture tools: the posture generator, the independent
// check and kinematics made once per guide, and the few ways the author asks
// for a posture (near a chosen one, accepted by the check) or reads the
// contacts a posture makes.
#include <optional>
#include <vector>

#include "planner/check/validity.h"
#include "planner/model/kinematics.h"
#include "planner/posture/posture_generator.h"
#include "planner/scene/scenario.h"

namespace acyclic {

// The posture generator (200 iterations, 2 s a call), the independent
// check, kinematics.
PostureGeneratorOptions guidePostureOptions();
struct PostureTools {
  explicit PostureTools(const Scenario& sc)
      : kin(sc.robot), pg(sc.robot, sc.scene, guidePostureOptions()), checker(sc.robot, sc.scene) {}
  Kinematics kin;
  PostureGenerator pg;
  ValidityChecker checker;
};

// A witness of `contacts` from `guess`, drawn toward `reference` (its joints
// weighed 0.01 of its base's place): a posture near a chosen one. nullopt
// when the posture generator finds none.
std::optional<Configuration> witnessNear(PostureGenerator& pg, const std::vector<ContactSpec>& contacts,
                                         const Configuration& guess, const Configuration& reference);

// witnessNear, and only a witness the independent check accepts on `contacts`.
std::optional<Configuration> checkedWitnessNear(PostureTools& t, const std::vector<ContactSpec>& contacts,
                                                const Configuration& guess, const Configuration& reference);

// The contacts a posture makes: each allowed spot within `distance` of an
// allowed surface's plane, over its polygon, its frame's z within `angle`
// of the surface's outward normal (as in contact), supporting, placed where
// the posture holds it. Each spot on one surface at most (the first the
// scenario lists).
std::vector<ContactSpec> contactsMadeBy(const Scenario& sc, Kinematics& kin, const Configuration& q,
                                        double distance = 0.01, double angle = 0.3);

}  // namespace acyclic
