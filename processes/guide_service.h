#pragma once
// The rough-trajectory author on LCM: answers every ACYCLIC_REQUEST whose
// scenario has no key postures with ACYCLIC_GUIDE (same request id).
#include <string>

#include "planner/guide/guide_author.h"

namespace acyclic {

int serveGuide(const std::string& lcm_url, const GuideOptions& options);

}  // namespace acyclic
