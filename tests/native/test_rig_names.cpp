// Rigs' own blendshape names onto ARKit's (stream/rig_names.h), from the table the Python and C#
// tests read too (tests/golden/names/rig_blendshape_names.tsv), and through the C ABI.
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "softdeca/softdeca.h"
#include "stream/arkit_names.h"
#include "stream/rig_names.h"

using namespace softdeca::stream;

namespace {
std::vector<std::pair<std::string, std::string>> table() {
  std::ifstream in(std::string(SOFTDECA_REPO_ROOT) + "/tests/golden/names/rig_blendshape_names.tsv");
  std::vector<std::pair<std::string, std::string>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line[0] == '#') continue;
    const auto tab = line.find('\t');
    if (tab == std::string::npos) continue;
    rows.emplace_back(line.substr(0, tab), line.substr(tab + 1));
  }
  return rows;
}
}  // namespace

TEST(RigNames, TheTableOfSpellingsMapsAsWritten) {
  const auto rows = table();
  ASSERT_GT(rows.size(), 30u);
  for (const auto& [name, want] : rows) {
    const int got = rig_blendshape_index(name);
    if (want == "-") {
      EXPECT_EQ(got, -1) << "'" << name << "'";
    } else {
      ASSERT_GE(got, 0) << "'" << name << "'";
      EXPECT_STREQ(blendshape_name(static_cast<std::size_t>(got)), want.c_str()) << "'" << name << "'";
    }
  }
}

TEST(RigNames, EveryCanonicalNameMapsToItself) {
  for (std::size_t i = 0; i < kBlendshapeCount; ++i) EXPECT_EQ(rig_blendshape_index(blendshape_name(i)), int(i));
}

TEST(RigNames, HostileNamesAreBoundedAndMatchNothing) {
  EXPECT_EQ(rig_blendshape_index(std::string(100000, 'a') + "jawOpen"), -1);
  EXPECT_EQ(rig_blendshape_index(std::string(300, '_')), -1);
  EXPECT_EQ(rig_blendshape_index(std::string("jaw\0Open", 8)), 24);  // a NUL separates words
  EXPECT_EQ(rig_blendshape_index("\xff\xfe" "jawOpen"), 24);       // so do other scripts' bytes
  EXPECT_EQ(rig_blendshape_index("\xe3\x81\xbe\xe3\x81\xb0"), -1);
}

TEST(RigNames, TheCAbiReportsTheIndexAndRefusesNull) {
  int32_t index = 99;
  ASSERT_EQ(softdeca_blendshape_find_index("blendShape1.jawOpen", &index), SOFTDECA_OK);
  EXPECT_EQ(index, 24);
  ASSERT_EQ(softdeca_blendshape_find_index("Basis", &index), SOFTDECA_OK);
  EXPECT_EQ(index, -1);
  EXPECT_EQ(softdeca_blendshape_find_index(nullptr, &index), SOFTDECA_ERROR_INVALID_ARGUMENT);
  EXPECT_EQ(softdeca_blendshape_find_index("jawOpen", nullptr), SOFTDECA_ERROR_INVALID_ARGUMENT);
}
