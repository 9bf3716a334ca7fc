// The storage precision per model of softdeca_avatar_desc: a zero-initialised desc gets the
// library's choice for each model (SoftDECA int8, SparseSoftDECA half), an explicit precision
// is honoured by its own model alone, and a value that is no softdeca_precision is refused with
// the field's name. Frames are compared bit for bit: one machine, one thread, the same kernels.
#include <cstring>
#include <string>
#include <vector>

#include "runtime_fixture.h"

namespace {
using namespace rt;

static_assert(SOFTDECA_PRECISION_DEFAULT == 0, "a zero-initialised desc must mean the library's choice");

// What an avatar gives for the same inputs: SoftDECA's frame, SparseSoftDECA's frame and the
// memory it holds once prepared.
struct Frames {
  std::vector<float> softdeca, sparse;
  uint64_t memory_bytes = 0;
};

bool same_bits(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

class StoragePrecision : public ::testing::Test {
 protected:
  void SetUp() override {
    REQUIRE_TEST_DATA();
    head = Head::load();
    ASSERT_EQ(softdeca_model_load((data_dir() + "/bundle").c_str(), nullptr, &model.p), SOFTDECA_OK) << softdeca_last_error();
    info.struct_size = sizeof info;
    ASSERT_EQ(softdeca_model_get_info(model.p, &info), SOFTDECA_OK);
    ASSERT_NE(info.has_sparse, 0) << "the test bundle has both models";
    weights.assign(52, 0.0f);
    weights[24] = 0.7f;  // jawOpen
    weights[3] = 0.4f;
    // The bundle's landmarks on the neutral, moved a few millimetres: what SparseSoftDECA reads.
    points.resize(3 * info.landmark_count);
    ASSERT_EQ(softdeca_model_evaluate_landmarks(model.p, head.neutral.data(), static_cast<uint32_t>(head.vertices()),
                                                points.data(), info.landmark_count),
              SOFTDECA_OK);
    for (std::size_t i = 0; i < points.size(); ++i) points[i] += 0.002f * static_cast<float>(i % 5) - 0.004f;
  }

  // The frames of the avatar `d` describes.
  void run(const Described& d, Frames& out) {
    AvatarPtr a;
    ASSERT_EQ(softdeca_avatar_create(model.p, &d, &a.p), SOFTDECA_OK) << softdeca_last_error();
    ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK) << softdeca_last_error();
    Buffers b(head.vertices());
    ASSERT_EQ(softdeca_avatar_evaluate_weights(a.p, weights.data(), 52, &b.out), SOFTDECA_OK) << softdeca_last_error();
    out.softdeca = b.vertices;
    ASSERT_EQ(softdeca_avatar_evaluate_landmarks(a.p, points.data(), info.landmark_count, &b.out), SOFTDECA_OK)
        << softdeca_last_error();
    out.sparse = b.vertices;
    softdeca_stats s{};
    s.struct_size = sizeof s;
    ASSERT_EQ(softdeca_avatar_get_stats(a.p, &s), SOFTDECA_OK);
    out.memory_bytes = s.memory_bytes;
  }

  // The frames with SoftDECA's tables at `precision` and SparseSoftDECA's at `sparse`.
  Frames at(int32_t precision, int32_t sparse) {
    Described d = describe(head);
    d.precision = precision;
    d.sparse_precision = sparse;
    Frames f;
    run(d, f);
    return f;
  }

  Head head;
  ModelPtr model;
  softdeca_model_info info{};
  std::vector<float> weights, points;
};

TEST_F(StoragePrecision, AZeroInitialisedDescGetsEachModelsDefault) {
  Described zero;  // every field zero but the two the call needs
  zero.struct_size = sizeof(softdeca_avatar_desc);
  zero.m = describe(head).m;
  Frames defaults;
  ASSERT_NO_FATAL_FAILURE(run(zero, defaults));
  const Frames int8_half = at(SOFTDECA_PRECISION_INT8, SOFTDECA_PRECISION_HALF);
  EXPECT_TRUE(same_bits(defaults.softdeca, int8_half.softdeca)) << "SoftDECA's default is int8";
  EXPECT_TRUE(same_bits(defaults.sparse, int8_half.sparse)) << "SparseSoftDECA's default is half";
  EXPECT_EQ(defaults.memory_bytes, int8_half.memory_bytes);
  // Neither frame is the same whatever the storage.
  EXPECT_FALSE(same_bits(defaults.softdeca, at(SOFTDECA_PRECISION_HALF, SOFTDECA_PRECISION_HALF).softdeca));
  EXPECT_FALSE(same_bits(defaults.sparse, at(SOFTDECA_PRECISION_INT8, SOFTDECA_PRECISION_INT8).sparse));
}

TEST_F(StoragePrecision, EachModelFollowsItsOwnPrecision) {
  const Frames int8_float = at(SOFTDECA_PRECISION_INT8, SOFTDECA_PRECISION_FLOAT);
  const Frames int8_half = at(SOFTDECA_PRECISION_INT8, SOFTDECA_PRECISION_HALF);
  const Frames float_half = at(SOFTDECA_PRECISION_FLOAT, SOFTDECA_PRECISION_HALF);
  // SparseSoftDECA's precision leaves SoftDECA's frame alone, and changes its own.
  EXPECT_TRUE(same_bits(int8_float.softdeca, int8_half.softdeca));
  EXPECT_FALSE(same_bits(int8_float.sparse, int8_half.sparse));
  EXPECT_GT(int8_float.memory_bytes, int8_half.memory_bytes) << "float holds twice half's bytes";
  // SoftDECA's leaves SparseSoftDECA's frame alone, and changes its own.
  EXPECT_TRUE(same_bits(float_half.sparse, int8_half.sparse));
  EXPECT_FALSE(same_bits(float_half.softdeca, int8_half.softdeca));
  EXPECT_GT(float_half.memory_bytes, int8_half.memory_bytes) << "float holds four times int8's bytes";
  // DEFAULT for one model is that model's default whatever the other's is.
  EXPECT_TRUE(same_bits(at(SOFTDECA_PRECISION_DEFAULT, SOFTDECA_PRECISION_FLOAT).softdeca, int8_float.softdeca));
  EXPECT_TRUE(same_bits(at(SOFTDECA_PRECISION_FLOAT, SOFTDECA_PRECISION_DEFAULT).sparse, float_half.sparse));
}

TEST_F(StoragePrecision, AValueThatIsNoPrecisionIsRefusedByName) {
  for (const int32_t bad : {-1, SOFTDECA_PRECISION_INT8 + 1, 99}) {
    for (const char* field : {"desc->precision", "desc->sparse_precision"}) {
      Described d = describe(head);
      (std::string(field) == "desc->precision" ? d.precision : d.sparse_precision) = bad;
      softdeca_avatar* a = nullptr;
      EXPECT_EQ(softdeca_avatar_create(model.p, &d, &a), SOFTDECA_ERROR_INVALID_ARGUMENT) << field << " " << bad;
      const std::string error = softdeca_last_error();
      EXPECT_NE(error.find(std::string(field) + " is " + std::to_string(bad)), std::string::npos) << error;
      EXPECT_EQ(a, nullptr);
    }
  }
}

}  // namespace
