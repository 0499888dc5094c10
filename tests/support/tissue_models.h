// The prostate tissue models the tissue tests share, built once per size per test binary
// (tetrahedralizing the larger glands takes seconds).
#pragma once

#include <gtest/gtest.h>

#include <map>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/scenes/prostate_tissue.h"

namespace resecto {

inline const ProstateTissueModel& tissue_model(int triangles) {
  static std::map<int, ProstateTissueModel> models;
  auto it = models.find(triangles);
  if (it == models.end()) {
    Result<ProstateTissueModel> model = build_prostate_tissue_model(generate_prostate(triangles), generate_resectoscope().loop);
    EXPECT_TRUE(model) << model.error();
    it = models.emplace(triangles, std::move(*model)).first;
  }
  return it->second;
}

}  // namespace resecto
