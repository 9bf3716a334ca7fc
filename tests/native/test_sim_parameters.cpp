// The parameter list p: one table from plugin/data/parameters.json, values validated, fields
// per element, revisions that tell the simulator what to rebuild.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "core/error.h"
#include "sim/parameters.h"

using namespace softdeca;
using namespace softdeca::sim;

namespace {
DomainSizes sizes() {
  DomainSizes s{};
  s.fill(5);
  return s;
}
}  // namespace

TEST(SimParameters, TableIsConsistent) {
  const auto& t = parameter_table();
  ASSERT_GE(t.size(), 20u);
  std::set<std::string> names;
  for (const auto& p : t) {
    EXPECT_TRUE(names.insert(p.name).second) << "duplicate " << p.name;
    EXPECT_LT(p.minimum, p.maximum) << p.name;
    EXPECT_GE(p.default_value, p.minimum) << p.name;
    EXPECT_LE(p.default_value, p.maximum) << p.name;
    if (p.log_scale) {
      EXPECT_GT(p.minimum, 0) << p.name;
    }
    EXPECT_GT(p.description.size(), 10u) << p.name;
    // The compiled-in JSON is the same file the table came from.
    EXPECT_NE(std::string(parameters_json()).find(std::string("\"name\": \"") + p.name + "\""), std::string::npos)
        << p.name;
  }
}

TEST(SimParameters, CoversAppendixA) {
  // Dynamics, every constraint weight (0.001..100, log), target volume, max strain, gravity,
  // cranium and jaw scale per axis, landmark regularisation.
  for (const char* n : {"dyn_gamma", "dyn_beta", "target_volume", "max_strain", "gravity_strength", "gravity_tilt",
                        "gravity_azimuth", "w_regularisation", "w_landmark"})
    EXPECT_NO_THROW(find_parameter(n)) << n;
  for (const char* bone : {"cranium", "jaw"})
    for (const char* axis : {"x", "y", "z"}) {
      const auto& spec = parameter_spec(find_parameter(std::string(bone) + "_scale_" + axis));
      EXPECT_EQ(spec.minimum, 0.5);
      EXPECT_EQ(spec.maximum, 1.5);
    }
  int weights = 0;
  for (const auto& p : parameter_table())
    if (p.name.rfind("w_", 0) == 0) {
      ++weights;
      EXPECT_EQ(p.minimum, 0.001) << p.name;
      EXPECT_EQ(p.maximum, 100.0) << p.name;
      EXPECT_TRUE(p.log_scale) << p.name;
      EXPECT_TRUE(parameter_refactors(find_parameter(p.name))) << p.name;
    }
  EXPECT_GE(weights, 12);
  EXPECT_EQ(parameter_spec(Param::target_volume).minimum, 0.5);
  EXPECT_EQ(parameter_spec(Param::max_strain).maximum, 1.3);
  EXPECT_EQ(parameter_spec(Param::gravity_strength).maximum, 2.0);
}

TEST(SimParameters, PhysicalConstantsComeFromTheFile) {
  const auto& k = physical_constants();
  EXPECT_EQ(k.pascal_per_weight_unit, 1000.0);
  EXPECT_NEAR(k.standard_gravity_m_s2, 9.80665, 1e-12);
  EXPECT_EQ(k.capture_gravity_direction, Eigen::Vector3d(0, -1, 0));
  EXPECT_GT(k.target_layer_thickness_m, 0);
}

TEST(SimParameters, OutOfRangeValuesAreRefusedWithNameAndRange) {
  ParameterSet p(sizes());
  try {
    p.set("w_soft_volume", 1000.0);
    FAIL() << "accepted an out-of-range weight";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), SOFTDECA_ERROR_INVALID_ARGUMENT);
    const std::string m = e.what();
    EXPECT_NE(m.find("w_soft_volume"), std::string::npos) << m;
    EXPECT_NE(m.find("[0.001, 100]"), std::string::npos) << m;
  }
  EXPECT_THROW(p.set("max_strain", 0.5), Error);
  EXPECT_THROW(p.set("dyn_beta", 1.0), Error);  // beta < 1 keeps the dynamics stable
  try {
    p.set("target_volume", std::nan(""));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), SOFTDECA_ERROR_NON_FINITE);
  }
  EXPECT_THROW(p.set("no_such_parameter", 1.0), Error);
  EXPECT_EQ(p.global(Param::w_soft_volume), parameter_spec(Param::w_soft_volume).default_value);
}

TEST(SimParameters, FieldsOverrideTheGlobalPerElement) {
  ParameterSet p(sizes());
  Eigen::VectorXd v(5);
  v << 1, 2, 3, 4, 5;
  p.set_field("w_soft_strain", v);
  EXPECT_TRUE(p.has_field(Param::w_soft_strain));
  EXPECT_EQ(p.at(Param::w_soft_strain, 3), 4.0);
  p.set("w_soft_strain", 7.0);  // a global value makes it uniform again
  EXPECT_FALSE(p.has_field(Param::w_soft_strain));
  EXPECT_EQ(p.at(Param::w_soft_strain, 3), 7.0);

  Eigen::VectorXd wrong(4);
  wrong.setOnes();
  try {
    p.set_field("w_soft_strain", wrong);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("soft_tet has 5 elements"), std::string::npos) << e.what();
  }
  v[2] = 500;
  try {
    p.set_field("w_soft_strain", v);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("w_soft_strain'[2]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(p.set_field("gravity_strength", Eigen::VectorXd::Ones(1)), Error);
}

TEST(SimParameters, RevisionsSeparateMatrixChanges) {
  ParameterSet p(sizes());
  const auto r = p.revision(), m = p.matrix_revision();
  p.set("target_volume", 1.2);  // enters the projection only
  EXPECT_GT(p.revision(), r);
  EXPECT_EQ(p.matrix_revision(), m);
  p.set("w_target", 3.0);  // a weight: refactorise
  EXPECT_GT(p.matrix_revision(), m);
}
