// The contact's candidate search against brute force (tests/support/contact_oracle.h), at poses
// from clear of the tissue to pressed into it, with both tool parts.
#include <gtest/gtest.h>

#include <vector>

#include "rtcore/anatomy/resectoscope.h"
#include "rtcore/scenes/indentation.h"
#include "rtcore/tissue/mass_spring.h"
#include "tests/support/contact_oracle.h"
#include "tests/support/tissue_models.h"

namespace resecto {
namespace {

class ContactSearch : public ::testing::TestWithParam<int> {};

TEST_P(ContactSearch, FindsEveryPairWithinTheMarginAndNoOther) {
  const ProstateTissueModel& model = tissue_model(GetParam());
  const ResectoscopeModel scope = generate_resectoscope();
  MassSpringTissue tissue(model.mesh, {}, {});
  const std::vector<TriangleMesh> parts = {model.loop, scope.sheath};
  const int loop = tissue.tool().add_part(model.loop);
  const int sheath = tissue.tool().add_part(scope.sheath);
  // The sheath rides with the loop's frame, so it lies across the lobe the loop presses: both parts
  // touch, at depths from just short of the crest (only the margin reaches) to 4 mm in.
  for (const double depth_mm : {-1.0, 0.0, 2.0, 4.0}) {
    const RigidPose pose = indentation_loop_pose(model.anatomy, model.loop, depth_mm * 1e-3);
    tissue.tool().reset_pose(loop, pose);
    tissue.tool().reset_pose(sheath, pose);
    for (int step = 0; step < 32; ++step) (void)tissue.physics_step(1.0 / 960.0);
    testing::expect_brute_force(tissue, parts, depth_mm < 0.0 ? "1 mm short" : "pressed");
  }
}

INSTANTIATE_TEST_SUITE_P(Glands, ContactSearch, ::testing::Values(1296, 8640));

}  // namespace
}  // namespace resecto
