// The runtime under threads: re-preparing while frames run never tears an output (each frame is
// wholly one preparation), a second thread on a busy avatar is refused instead of racing, and
// avatars run in parallel with the same results as alone; helper threads give the same output.
#include <atomic>
#include <cmath>
#include <string>
#include <thread>
#include <vector>

#include "runtime_fixture.h"

namespace {
using namespace rt;

double max_diff(const std::vector<float>& a, const std::vector<float>& b) {
  double d = 0;
  for (std::size_t i = 0; i < a.size(); ++i) d = std::max(d, double(std::fabs(a[i] - b[i])));
  return d;
}

class Threads : public ::testing::Test {
 protected:
  void SetUp() override {
    REQUIRE_TEST_DATA();
    head = Head::load();
    ASSERT_EQ(softdeca_model_load((data_dir() + "/bundle").c_str(), nullptr, &model.p), SOFTDECA_OK) << softdeca_last_error();
    ASSERT_EQ(softdeca_model_find_parameter(model.p, "w_skin_strain", &strain), SOFTDECA_OK);
    weights.assign(52, 0.0f);
    weights[24] = 0.8f;
    weights[44] = 0.5f;
  }
  std::vector<float> frame(softdeca_avatar* a) {
    Buffers b(head.vertices());
    EXPECT_EQ(softdeca_avatar_evaluate_weights(a, weights.data(), 52, &b.out), SOFTDECA_OK) << softdeca_last_error();
    return b.vertices;
  }
  Head head;
  ModelPtr model;
  uint32_t strain = 0;
  std::vector<float> weights;
};

TEST_F(Threads, ReprepareWhileFramesRunNeverTearsAnOutput) {
  AvatarPtr a;
  const auto d = describe(head);
  ASSERT_EQ(softdeca_avatar_create(model.p, &d, &a.p), SOFTDECA_OK);
  // The two outputs the two parameter sets give.
  ASSERT_EQ(softdeca_avatar_set_parameter(a.p, strain, 0.01f), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK);
  const auto out_a = frame(a.p);
  ASSERT_EQ(softdeca_avatar_set_parameter(a.p, strain, 90.0f), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK);
  const auto out_b = frame(a.p);
  const double gap = max_diff(out_a, out_b);
  ASSERT_GT(gap, 1e-5) << "the two parameter sets must give visibly different outputs";

  std::atomic<bool> stop{false};
  std::atomic<int> preparations{0};
  std::thread preparer([&] {
    for (int i = 0; !stop.load(); ++i) {
      ASSERT_EQ(softdeca_avatar_set_parameter(a.p, strain, i % 2 ? 90.0f : 0.01f), SOFTDECA_OK);
      ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK) << softdeca_last_error();
      preparations.fetch_add(1);
    }
  });
  int seen_a = 0, seen_b = 0, torn = 0, frames = 0;
  Buffers b(head.vertices());
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while ((seen_a < 20 || seen_b < 20 || preparations.load() < 20) && std::chrono::steady_clock::now() < deadline) {
    ASSERT_EQ(softdeca_avatar_evaluate_weights(a.p, weights.data(), 52, &b.out), SOFTDECA_OK) << softdeca_last_error();
    ++frames;
    const double da = max_diff(b.vertices, out_a), db = max_diff(b.vertices, out_b);
    if (da < 1e-6) ++seen_a;
    else if (db < 1e-6) ++seen_b;
    else ++torn;
  }
  stop.store(true);
  preparer.join();
  EXPECT_EQ(torn, 0) << "frames that were neither preparation's output, of " << frames;
  EXPECT_GE(seen_a, 20) << frames << " frames, " << preparations.load() << " preparations";
  EXPECT_GE(seen_b, 20) << frames << " frames, " << preparations.load() << " preparations";
}

TEST_F(Threads, ASecondFrameThreadIsRefusedNotRaced) {
  AvatarPtr a;
  const auto d = describe(head);
  ASSERT_EQ(softdeca_avatar_create(model.p, &d, &a.p), SOFTDECA_OK);
  ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK);
  const auto expected = frame(a.p);
  std::atomic<int> ok{0}, busy{0}, other{0}, wrong{0};
  auto worker = [&] {
    Buffers b(head.vertices());
    for (int i = 0; i < 300; ++i) {
      const softdeca_status s = softdeca_avatar_evaluate_weights(a.p, weights.data(), 52, &b.out);
      if (s == SOFTDECA_OK) {
        ok.fetch_add(1);
        if (max_diff(b.vertices, expected) > 1e-6) wrong.fetch_add(1);
      } else if (s == SOFTDECA_ERROR_BUSY) {
        busy.fetch_add(1);
      } else {
        other.fetch_add(1);
      }
    }
  };
  std::thread t1(worker), t2(worker);
  t1.join();
  t2.join();
  EXPECT_EQ(other.load(), 0);
  EXPECT_EQ(wrong.load(), 0);
  EXPECT_GT(ok.load(), 0);
  EXPECT_EQ(ok.load() + busy.load(), 600);
}

TEST_F(Threads, AvatarsRunInParallelLikeAlone) {
  constexpr int kAvatars = 4;
  std::vector<std::vector<float>> alone(kAvatars);
  std::vector<std::vector<float>> weights_of(kAvatars, weights);
  for (int i = 0; i < kAvatars; ++i) {
    weights_of[i][10 + i] = 0.3f + 0.1f * static_cast<float>(i);
    AvatarPtr a;
    const auto d = describe(head);
    ASSERT_EQ(softdeca_avatar_create(model.p, &d, &a.p), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK);
    Buffers b(head.vertices());
    ASSERT_EQ(softdeca_avatar_evaluate_weights(a.p, weights_of[i].data(), 52, &b.out), SOFTDECA_OK);
    alone[i] = b.vertices;
  }
  std::atomic<int> mismatches{0}, failures{0};
  std::vector<std::thread> threads;
  for (int i = 0; i < kAvatars; ++i)
    threads.emplace_back([&, i] {
      AvatarPtr a;
      const auto d = describe(head, 1 + static_cast<uint32_t>(i % 2));  // half of them with a helper thread
      if (softdeca_avatar_create(model.p, &d, &a.p) != SOFTDECA_OK || softdeca_avatar_prepare(a.p) != SOFTDECA_OK) {
        failures.fetch_add(1);
        return;
      }
      Buffers b(head.vertices());
      for (int f = 0; f < 50; ++f) {
        if (softdeca_avatar_evaluate_weights(a.p, weights_of[i].data(), 52, &b.out) != SOFTDECA_OK) failures.fetch_add(1);
        if (max_diff(b.vertices, alone[i]) > 1e-6) mismatches.fetch_add(1);
      }
    });
  for (auto& t : threads) t.join();
  EXPECT_EQ(failures.load(), 0);
  EXPECT_EQ(mismatches.load(), 0);
}

TEST_F(Threads, HelperThreadsGiveTheSameOutput) {
  std::vector<float> ref_v, ref_n, ref_l;
  for (const uint32_t threads : {1u, 2u, 3u}) {
    AvatarPtr a;
    const auto d = describe(head, threads);
    ASSERT_EQ(softdeca_avatar_create(model.p, &d, &a.p), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_set_dynamics(a.p, SOFTDECA_TRUE), SOFTDECA_OK);
    Buffers b(head.vertices()), l(head.vertices());
    for (int f = 0; f < 5; ++f) ASSERT_EQ(softdeca_avatar_evaluate_weights(a.p, weights.data(), 52, &b.out), SOFTDECA_OK);
    const auto pts = head.user_face(weights.data());
    ASSERT_EQ(softdeca_avatar_evaluate_landmarks(a.p, pts.data(), head.user_vertices(), &l.out), SOFTDECA_OK);
    softdeca_stats s{};
    s.struct_size = sizeof s;
    ASSERT_EQ(softdeca_avatar_get_stats(a.p, &s), SOFTDECA_OK);
    EXPECT_EQ(s.threads, threads);
    if (threads == 1) {
      ref_v = b.vertices;
      ref_n = b.normals;
      ref_l = l.vertices;
      continue;
    }
    // Summation order of the right-hand side differs across threads: float round-off only.
    EXPECT_LT(max_diff(b.vertices, ref_v), 1e-6) << threads;
    EXPECT_LT(max_diff(b.normals, ref_n), 1e-5) << threads;
    EXPECT_LT(max_diff(l.vertices, ref_l), 1e-7) << threads;
  }
}

}  // namespace
