// The ONNX Runtime root (headers from one source, library from another) is usable: the API
// version the headers ask for is served by the library.
#include <gtest/gtest.h>
#include <onnxruntime_c_api.h>

#include <string>

TEST(OnnxRuntimeRoot, ServesTheHeadersApiVersion) {
  const OrtApiBase* base = OrtGetApiBase();
  ASSERT_NE(base, nullptr);
  const std::string version = base->GetVersionString();
  EXPECT_FALSE(version.empty());
  const OrtApi* api = base->GetApi(ORT_API_VERSION);
  ASSERT_NE(api, nullptr) << "library " << version << " lacks API " << ORT_API_VERSION;
  OrtEnv* env = nullptr;
  OrtStatus* st = api->CreateEnv(ORT_LOGGING_LEVEL_WARNING, "test", &env);
  ASSERT_EQ(st, nullptr);
  api->ReleaseEnv(env);
}
