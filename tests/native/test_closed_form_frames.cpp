// Frames of a bundle at SoftDECA's closed-form start (DT at identity, the vertex and residual
// stages on: the runtime tests' bundle_closed_form), as the committed bundle runs them: the
// template's frame, written straight into the caller's output, is the frame the checked path
// makes (a whole-head surface runs that one) bit for bit, at the defaults and with the physics
// at prepare's offset.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "runtime_fixture.h"

namespace {
using namespace rt;

TEST(ClosedFormFrames, TheFrameWrittenInPlaceIsTheCheckedFrame) {
  REQUIRE_TEST_DATA();
  const Head head = Head::load();
  ModelPtr model;
  ASSERT_EQ(softdeca_model_load((data_dir() + "/bundle_closed_form").c_str(), nullptr, &model.p), SOFTDECA_OK)
      << softdeca_last_error();
  AvatarPtr avatar;
  const auto d = describe(head, 1, SOFTDECA_PRECISION_FLOAT);
  ASSERT_EQ(softdeca_avatar_create(model.p, &d, &avatar.p), SOFTDECA_OK) << softdeca_last_error();
  const std::size_t n = head.vertices();
  at_defaults_and_a_rest_offset(model.p, avatar.p, 4, [&](const std::vector<float>& w, const std::string& what) {
    Buffers in_place(n, NAN), linear(n), checked(n, NAN);
    ASSERT_EQ(softdeca_avatar_evaluate_weights(avatar.p, w.data(), 52, &in_place.out), SOFTDECA_OK) << softdeca_last_error();
    ASSERT_EQ(softdeca_avatar_evaluate_linear(avatar.p, w.data(), 52, &linear.out), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_evaluate_surface(avatar.p, w.data(), 52, linear.vertices.data(), static_cast<uint32_t>(n),
                                               &checked.out),
              SOFTDECA_OK)
        << softdeca_last_error();
    EXPECT_EQ(in_place.vertices, checked.vertices) << what;
    EXPECT_EQ(in_place.normals, checked.normals) << what;
    double moved = 0;
    for (std::size_t i = 0; i < 3 * n; ++i) moved = std::max(moved, double(std::fabs(in_place.vertices[i] - linear.vertices[i])));
    EXPECT_GT(moved, 1e-5) << "the stages correct the blend";
  });
}

}  // namespace
