// The hot path allocates nothing of its own: after warm-up, a frame makes exactly as many calls to
// operator new as ONNX Runtime makes for one run of the per-frame network alone (its execution
// frame), and frames without a network make none. Counted by replacing operator new in this
// test binary (ONNX Runtime uses the same one).
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>

#include "bundle/bundle_files.h"
#include "runtime/model.h"
#include "runtime_fixture.h"

namespace {
std::atomic<long> g_allocations{0};
std::atomic<bool> g_counting{false};

void* counted(std::size_t n) {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
  void* p = std::malloc(n ? n : 1);
  if (!p) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t n) { return counted(n); }
void* operator new[](std::size_t n) { return counted(n); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted(n);
  } catch (...) {
    return nullptr;
  }
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  try {
    return counted(n);
  } catch (...) {
    return nullptr;
  }
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace {
using namespace rt;

struct Counting {
  Counting() {
    g_allocations.store(0);
    g_counting.store(true);
  }
  ~Counting() { g_counting.store(false); }
  long count() const { return g_allocations.load(); }
};

// operator new calls per call of `f`, averaged over `n` calls after `warmup` calls.
template <class F>
double allocations_per_call(F&& f, int n = 40, int warmup = 5) {
  for (int i = 0; i < warmup; ++i) f(i);
  Counting counting;
  for (int i = 0; i < n; ++i) f(i);
  return static_cast<double>(counting.count()) / n;
}

TEST(RuntimeAllocations, FramesAllocateNothingBeyondOnnxRuntime) {
  REQUIRE_TEST_DATA();
  const Head head = Head::load();
  // ONNX Runtime alone: one run of each per-frame network over fixed buffers.
  const auto files = softdeca::bundle::BundleFiles::from_path(data_dir() + "/bundle");
  const auto bare = softdeca::runtime::Model::load(files, {});
  std::vector<float> w(52, 0.2f), z(32), offsets(3 * bare->manifest().landmarks.size(), 0.001f);
  auto f_w = bare->encoder(false)->bind({w.data()}, {z.data()}, 1);
  auto f_l = bare->encoder(true)->bind({offsets.data()}, {z.data()}, 1);
  const double ort_w = allocations_per_call([&](int) { bare->encoder(false)->run(f_w); });
  const double ort_l = allocations_per_call([&](int) { bare->encoder(true)->run(f_l); });
  std::printf("ONNX Runtime alone: %.1f operator new calls per f_w run, %.1f per f_l run\n", ort_w, ort_l);
  ModelPtr model;
  ASSERT_EQ(softdeca_model_load((data_dir() + "/bundle").c_str(), nullptr, &model.p), SOFTDECA_OK) << softdeca_last_error();
  for (const uint32_t threads : {1u, 2u}) {
    AvatarPtr a;
    const auto d = describe(head, threads);
    ASSERT_EQ(softdeca_avatar_create(model.p, &d, &a.p), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_prepare(a.p), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_set_dynamics(a.p, SOFTDECA_TRUE), SOFTDECA_OK);
    ASSERT_EQ(softdeca_avatar_calibrate_landmarks(a.p, head.user_neutral.data(), head.user_vertices()), SOFTDECA_OK);
    Buffers b(head.vertices());
    std::vector<std::vector<float>> weights(8, std::vector<float>(52, 0.0f)), faces;
    for (std::size_t f = 0; f < weights.size(); ++f) {
      weights[f][f * 5 % 52] = 0.5f;
      weights[f][24] = 0.1f * static_cast<float>(f);
      faces.push_back(head.user_face(weights[f].data()));
    }
    softdeca_stats s{};
    s.struct_size = sizeof s;
    const auto frame = [&](int i) { return weights[static_cast<std::size_t>(i) % weights.size()].data(); };
    const double linear = allocations_per_call([&](int i) {
      ASSERT_EQ(softdeca_avatar_evaluate_linear(a.p, frame(i), 52, &b.out), SOFTDECA_OK);
      ASSERT_EQ(softdeca_avatar_get_stats(a.p, &s), SOFTDECA_OK);
    });
    const double softdeca = allocations_per_call([&](int i) {
      ASSERT_EQ(softdeca_avatar_evaluate_weights(a.p, frame(i), 52, &b.out), SOFTDECA_OK);
    });
    const double surface = allocations_per_call([&](int i) {
      ASSERT_EQ(softdeca_avatar_evaluate_surface(a.p, frame(i), 52, head.neutral.data(), head.vertices(), &b.out), SOFTDECA_OK);
    });
    const double sparse = allocations_per_call([&](int i) {
      ASSERT_EQ(softdeca_avatar_evaluate_landmarks(a.p, faces[static_cast<std::size_t>(i) % faces.size()].data(),
                                                   head.user_vertices(), &b.out),
                SOFTDECA_OK);
    });
    EXPECT_EQ(linear, 0.0) << "threads " << threads;
    EXPECT_EQ(softdeca, ort_w) << "threads " << threads;
    EXPECT_EQ(surface, ort_w) << "threads " << threads;
    EXPECT_EQ(sparse, ort_l) << "threads " << threads;
  }
}

}  // namespace
