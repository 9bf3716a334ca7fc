// softdeca_avatar_evaluate_weights_batch: each avatar's frame equals its own call's, with the
// frame networks run once for the batch (avatars with other parameters form their own residual
// group); each avatar gets the status its own call would return, and a call that is itself
// wrong evaluates nothing.
#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "runtime_fixture.h"

namespace {
using namespace rt;

class RuntimeBatch : public ::testing::Test {
 protected:
  void SetUp() override {
    REQUIRE_TEST_DATA();
    head = Head::load();
    ASSERT_EQ(softdeca_model_load((data_dir() + "/bundle").c_str(), nullptr, &model.p), SOFTDECA_OK) << softdeca_last_error();
    ASSERT_EQ(softdeca_model_find_parameter(model.p, "gravity_strength", &gravity), SOFTDECA_OK);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    weights.resize(kAvatars * 52);
    for (float& w : weights) w = unit(rng) * unit(rng);
  }

  // An avatar in the template's topology at the library's default precisions, prepared, with
  // `g` times the default gravity.
  void make(AvatarPtr& a, double g, bool prepare = true) {
    Described d = describe(head, 1, SOFTDECA_PRECISION_DEFAULT);
    ASSERT_EQ(softdeca_avatar_create(model.p, &d, &a.p), SOFTDECA_OK) << softdeca_last_error();
    ASSERT_EQ(softdeca_avatar_set_parameter(a.p, gravity, g), SOFTDECA_OK);
    if (prepare) {
      ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK) << softdeca_last_error();
    }
  }

  static constexpr std::size_t kAvatars = 4;
  Head head;
  ModelPtr model;
  uint32_t gravity = 0;
  std::vector<float> weights;
};

float max_difference(const std::vector<float>& a, const std::vector<float>& b) {
  float d = 0.0f;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, std::fabs(a[i] - b[i]));
  return d;
}

TEST_F(RuntimeBatch, EachFrameEqualsTheAvatarsOwnCall) {
  // avatars 0, 1 and 3 share the default parameters (one residual group), avatar 2 has twice the
  // gravity (a group of its own)
  AvatarPtr a[kAvatars];
  for (std::size_t i = 0; i < kAvatars; ++i) make(a[i], i == 2 ? 2.0 : 1.0);
  std::vector<Buffers> own, batched;
  std::vector<softdeca_avatar*> handles;
  std::vector<softdeca_output> outputs;
  for (std::size_t i = 0; i < kAvatars; ++i) {
    own.emplace_back(head.vertices());
    batched.emplace_back(head.vertices());
  }
  for (std::size_t i = 0; i < kAvatars; ++i) {
    ASSERT_EQ(softdeca_avatar_evaluate_weights(a[i].p, weights.data() + 52 * i, 52, &own[i].out), SOFTDECA_OK)
        << softdeca_last_error();
    handles.push_back(a[i].p);
    outputs.push_back(batched[i].out);
  }
  std::vector<int32_t> statuses(kAvatars, -1);
  ASSERT_EQ(softdeca_avatar_evaluate_weights_batch(handles.data(), kAvatars, weights.data(), 52, outputs.data(),
                                                   statuses.data()),
            SOFTDECA_OK)
      << softdeca_last_error();
  for (std::size_t i = 0; i < kAvatars; ++i) {
    EXPECT_EQ(statuses[i], SOFTDECA_OK) << i;
    // The networks' sums for a batch may run in another order than for one frame (float
    // rounding, about 1e-7 of a code); the frame moves by that share of its correction.
    EXPECT_LT(max_difference(own[i].vertices, batched[i].vertices), 1e-7f) << "avatar " << i;
    EXPECT_LT(max_difference(own[i].normals, batched[i].normals), 1e-5f) << "avatar " << i;
  }
  // the gravity moved avatar 2's frame: its own residual group, not another's codes
  EXPECT_GT(max_difference(batched[2].vertices, batched[0].vertices), 1e-6f);
  softdeca_stats s{};
  s.struct_size = sizeof s;
  ASSERT_EQ(softdeca_avatar_get_stats(a[0].p, &s), SOFTDECA_OK);
  EXPECT_EQ(s.frames, 2u);  // its own call and the batch's
}

TEST_F(RuntimeBatch, EachAvatarGetsItsOwnCallsStatus) {
  AvatarPtr ready, unprepared, other;
  make(ready, 1.0);
  make(unprepared, 1.0, false);
  make(other, 1.0);
  std::vector<float> w = weights;
  w[2 * 52 + 5] = NAN;  // the third avatar's weights
  const float sentinel = 12345.0f;
  Buffers b0(head.vertices(), sentinel), b1(head.vertices(), sentinel), b2(head.vertices(), sentinel);
  softdeca_avatar* handles[] = {ready.p, unprepared.p, other.p};
  const softdeca_output outputs[] = {b0.out, b1.out, b2.out};
  int32_t statuses[3] = {-1, -1, -1};
  ASSERT_EQ(softdeca_avatar_evaluate_weights_batch(handles, 3, w.data(), 52, outputs, statuses), SOFTDECA_OK);
  EXPECT_EQ(statuses[0], SOFTDECA_OK);
  Buffers alone(head.vertices(), sentinel);
  EXPECT_EQ(statuses[1], softdeca_avatar_evaluate_weights(unprepared.p, w.data() + 52, 52, &alone.out));
  EXPECT_EQ(statuses[1], SOFTDECA_ERROR_NOT_READY);
  EXPECT_EQ(statuses[2], softdeca_avatar_evaluate_weights(other.p, w.data() + 104, 52, &alone.out));
  EXPECT_NE(statuses[2], SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_evaluate_weights_batch(handles, 3, w.data(), 52, outputs, statuses), SOFTDECA_OK);
  // the first failure's message, naming the avatar
  EXPECT_NE(std::string(softdeca_last_error()).find("avatar 1:"), std::string::npos) << softdeca_last_error();
  EXPECT_NE(b0.vertices[0], sentinel);  // written
  for (const float v : b1.vertices) ASSERT_EQ(v, sentinel);  // untouched
  for (const float v : b2.vertices) ASSERT_EQ(v, sentinel);
}

TEST_F(RuntimeBatch, AWrongCallEvaluatesNothing) {
  AvatarPtr a;
  make(a, 1.0);
  const float sentinel = 12345.0f;
  Buffers b(head.vertices(), sentinel);
  softdeca_avatar* handles[] = {a.p};
  int32_t statuses[1] = {-1};
  EXPECT_EQ(softdeca_avatar_evaluate_weights_batch(nullptr, 1, weights.data(), 52, &b.out, statuses),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_evaluate_weights_batch(handles, 1, nullptr, 52, &b.out, statuses), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_evaluate_weights_batch(handles, 1, weights.data(), 52, nullptr, statuses),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_evaluate_weights_batch(handles, 1, weights.data(), 52, &b.out, nullptr),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_avatar_evaluate_weights_batch(handles, 0, weights.data(), 52, &b.out, statuses),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_NE(std::string(softdeca_last_error()).find("1 to 4096"), std::string::npos) << softdeca_last_error();
  EXPECT_EQ(softdeca_avatar_evaluate_weights_batch(handles, 4097, weights.data(), 52, &b.out, statuses),
            SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(statuses[0], -1);
  for (const float v : b.vertices) ASSERT_EQ(v, sentinel);
  // a null handle in the array is that avatar's failure, as its own call's
  softdeca_avatar* with_null[] = {a.p, nullptr};
  Buffers c(head.vertices(), sentinel);
  const softdeca_output two[] = {b.out, c.out};
  int32_t both[2] = {-1, -1};
  ASSERT_EQ(softdeca_avatar_evaluate_weights_batch(with_null, 2, weights.data(), 52, two, both), SOFTDECA_OK);
  EXPECT_EQ(both[0], SOFTDECA_OK);
  EXPECT_EQ(both[1], SOFTDECA_ERROR_INVALID_ARGUMENT);
  // a weight count other than 52 is each avatar's refusal, as its own call's
  ASSERT_EQ(softdeca_avatar_evaluate_weights_batch(handles, 1, weights.data(), 51, &b.out, statuses), SOFTDECA_OK);
  EXPECT_EQ(statuses[0], SOFTDECA_ERROR_INVALID_ARGUMENT);
}

TEST_F(RuntimeBatch, TheSameAvatarTwiceRunsTwoFramesInTurn) {
  AvatarPtr a;
  make(a, 1.0);
  Buffers b0(head.vertices()), b1(head.vertices());
  softdeca_avatar* handles[] = {a.p, a.p};
  const softdeca_output outputs[] = {b0.out, b1.out};
  int32_t statuses[2] = {-1, -1};
  std::vector<float> w(weights.begin(), weights.begin() + 104);
  std::memcpy(w.data() + 52, w.data(), 52 * sizeof(float));
  ASSERT_EQ(softdeca_avatar_evaluate_weights_batch(handles, 2, w.data(), 52, outputs, statuses), SOFTDECA_OK);
  EXPECT_EQ(statuses[0], SOFTDECA_OK);
  EXPECT_EQ(statuses[1], SOFTDECA_OK);
  EXPECT_EQ(b0.vertices, b1.vertices);
}

}  // namespace
