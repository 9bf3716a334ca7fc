// The material and simulation parameter vector p (paper section 3.3.3, Appendix A).
// The list itself lives in plugin/data/parameters.json, compiled into the library; this file
// gives it a C++ face: an immutable table of ParameterSpecs (core/parameter_spec.h), the
// simulator's own facts per parameter (its element kind, whether it changes the system matrix),
// and ParameterSet, the values one simulator uses, global or per element ("localised", paper
// section 3.5.2).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/parameter_spec.h"
#include "sim/parameter_table.h"  // generated from plugin/data/parameters.json

namespace softdeca::sim {

// Where per-element values of a parameter live. The element counts come from the mesh.
enum class Domain {
  kGlobal,
  kSoftTet,
  kMuscleTet,
  kConnectingTet,
  kSkinTriangle,
  kSkullTriangle,
  kVertex,
  kSkinPoint,
  kLandmark,
};
constexpr int kDomainCount = 9;

// Compile-time handles, in the order of parameters.json.
#define SOFTDECA_PARAMETER_ID(id, ...) id,
enum class Param : int { SOFTDECA_PARAMETER_TABLE(SOFTDECA_PARAMETER_ID) };
#undef SOFTDECA_PARAMETER_ID

// Physical constants of the same file ("constants").
struct PhysicalConstants {
  double pascal_per_weight_unit;
  double tissue_density_kg_m3;
  double standard_gravity_m_s2;
  Eigen::Vector3d capture_gravity_direction;
  double skin_thickness_m;
  double skull_shell_thickness_m;
  double target_layer_thickness_m;
};

// The list in Param's order; static, built once.
const std::vector<ParameterSpec>& parameter_table();
const ParameterSpec& parameter_spec(Param p);
// The element kind per-element values of p are given for (its spec's domain, as an enum).
Domain parameter_domain(Param p);
// Whether a change of p alters the system matrix ("refactor" in parameters.json).
bool parameter_refactors(Param p);
const PhysicalConstants& physical_constants();
// The JSON file verbatim, as compiled in.
const char* parameters_json();
const char* domain_name(Domain d);

// Index of a parameter by name; throws Error (invalid argument) naming the known ones.
Param find_parameter(std::string_view name);

// Throws Error when value is not finite or outside [minimum, maximum]; the message names the parameter,
// the value and the range.
void check_parameter_value(Param p, double value, const std::string& where = "");

// Element counts per domain (kGlobal is 1).
using DomainSizes = std::array<std::size_t, kDomainCount>;

// The values of p for one simulator: a global value per parameter, optionally overridden per
// element by a field. Bookkeeping counters let the simulator rebuild only what changed.
class ParameterSet {
 public:
  explicit ParameterSet(const DomainSizes& sizes);

  double global(Param p) const { return global_[index(p)]; }
  // The value at element i of the parameter's domain: the field's entry, else the global.
  double at(Param p, Eigen::Index i) const {
    const auto& f = field_[index(p)];
    return f.size() ? f[i] : global_[index(p)];
  }
  bool has_field(Param p) const { return field_[index(p)].size() > 0; }
  const Eigen::VectorXd& field(Param p) const { return field_[index(p)]; }

  // Sets the global value and drops any per-element field (the value becomes uniform).
  void set(Param p, double value);
  void set(std::string_view name, double value) { set(find_parameter(name), value); }
  // Per-element values; size must match the domain's element count. Global parameters refuse.
  void set_field(Param p, const Eigen::VectorXd& values);
  void set_field(std::string_view name, const Eigen::VectorXd& values) {
    set_field(find_parameter(name), values);
  }
  void clear_field(Param p);
  void reset_to_defaults();

  std::size_t domain_size(Domain d) const { return sizes_[static_cast<std::size_t>(d)]; }
  // Incremented on every change / on changes of parameters that alter the system matrix.
  std::uint64_t revision() const { return revision_; }
  std::uint64_t matrix_revision() const { return matrix_revision_; }

 private:
  static std::size_t index(Param p) { return static_cast<std::size_t>(p); }
  void touched(Param p);

  DomainSizes sizes_;
  std::vector<double> global_;
  std::vector<Eigen::VectorXd> field_;
  std::uint64_t revision_ = 0;
  std::uint64_t matrix_revision_ = 0;
};

}  // namespace softdeca::sim
