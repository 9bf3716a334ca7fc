#include "sim/parameters.h"

#include <cmath>
#include <sstream>

#include "core/error.h"

namespace softdeca::sim {
namespace {
// The generated table names scales and domains as bare words.
constexpr bool linear = false;
constexpr bool log = true;
constexpr Domain global = Domain::kGlobal;
constexpr Domain soft_tet = Domain::kSoftTet;
constexpr Domain muscle_tet = Domain::kMuscleTet;
constexpr Domain connecting_tet = Domain::kConnectingTet;
constexpr Domain skin_triangle = Domain::kSkinTriangle;
constexpr Domain skull_triangle = Domain::kSkullTriangle;
constexpr Domain vertex = Domain::kVertex;
constexpr Domain skin_point = Domain::kSkinPoint;
constexpr Domain landmark = Domain::kLandmark;

#define SOFTDECA_PARAMETER_DOMAIN(id, name, symbol, def, minimum, maximum, log_scale, unit, domain, refactor, \
                                  description)                                                                \
  domain,
constexpr Domain kDomains[] = {SOFTDECA_PARAMETER_TABLE(SOFTDECA_PARAMETER_DOMAIN)};
#undef SOFTDECA_PARAMETER_DOMAIN
#define SOFTDECA_PARAMETER_REFACTOR(id, name, symbol, def, minimum, maximum, log_scale, unit, domain, refactor, \
                                    description)                                                                \
  refactor,
constexpr bool kRefactors[] = {SOFTDECA_PARAMETER_TABLE(SOFTDECA_PARAMETER_REFACTOR)};
#undef SOFTDECA_PARAMETER_REFACTOR

std::size_t row(Param p) { return static_cast<std::size_t>(p); }

std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

const std::vector<ParameterSpec>& parameter_table() {
#define SOFTDECA_PARAMETER_ROW(id, name, symbol, def, minimum, maximum, log_scale, unit, domain, refactor, \
                               description)                                                                \
  ParameterSpec{name, symbol, unit, domain_name(domain), description, def, minimum, maximum, log_scale, domain != global},
  static const std::vector<ParameterSpec> table = {SOFTDECA_PARAMETER_TABLE(SOFTDECA_PARAMETER_ROW)};
#undef SOFTDECA_PARAMETER_ROW
  return table;
}

const ParameterSpec& parameter_spec(Param p) { return parameter_table()[row(p)]; }

Domain parameter_domain(Param p) { return kDomains[row(p)]; }

bool parameter_refactors(Param p) { return kRefactors[row(p)]; }

const PhysicalConstants& physical_constants() {
  static const PhysicalConstants c = [] {
    PhysicalConstants k{};
#define SOFTDECA_CONSTANT_NUMBER(key, value) k.key = value;
#define SOFTDECA_CONSTANT_ARRAY(key, n, ...) \
  {                                          \
    const double v[n] = __VA_ARGS__;         \
    for (int i = 0; i < n; ++i) k.key[i] = v[i]; \
  }
    SOFTDECA_PARAMETER_CONSTANTS(SOFTDECA_CONSTANT_NUMBER, SOFTDECA_CONSTANT_ARRAY)
#undef SOFTDECA_CONSTANT_NUMBER
#undef SOFTDECA_CONSTANT_ARRAY
    return k;
  }();
  return c;
}

const char* parameters_json() {
  return
#include "sim/parameters_json.inc"
      ;
}

const char* domain_name(Domain d) {
  switch (d) {
    case Domain::kGlobal: return "global";
    case Domain::kSoftTet: return "soft_tet";
    case Domain::kMuscleTet: return "muscle_tet";
    case Domain::kConnectingTet: return "connecting_tet";
    case Domain::kSkinTriangle: return "skin_triangle";
    case Domain::kSkullTriangle: return "skull_triangle";
    case Domain::kVertex: return "vertex";
    case Domain::kSkinPoint: return "skin_point";
    case Domain::kLandmark: return "landmark";
  }
  return "unknown";
}

Param find_parameter(std::string_view name) {
  const auto& t = parameter_table();
  for (std::size_t i = 0; i < t.size(); ++i)
    if (name == t[i].name) return static_cast<Param>(i);
  std::string known;
  for (const auto& p : t) known += std::string(known.empty() ? "" : ", ") + p.name;
  throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT,
              "unknown parameter '" + std::string(name) + "' (known: " + known + ")");
}

void check_parameter_value(Param p, double value, const std::string& where) {
  const ParameterSpec& spec = parameter_spec(p);
  if (!std::isfinite(value))
    throw Error(SOFTDECA_ERROR_NON_FINITE, "parameter '" + spec.name + "'" + where + " is not finite");
  if (value < spec.minimum || value > spec.maximum)
    throw Error(SOFTDECA_ERROR_INVALID_ARGUMENT,
                "parameter '" + spec.name + "'" + where + " = " + format_number(value) + " is outside its range [" +
                    format_number(spec.minimum) + ", " + format_number(spec.maximum) + "]");
}

ParameterSet::ParameterSet(const DomainSizes& sizes) : sizes_(sizes) {
  sizes_[static_cast<std::size_t>(Domain::kGlobal)] = 1;
  field_.resize(parameter_table().size());
  reset_to_defaults();
}

void ParameterSet::reset_to_defaults() {
  const auto& t = parameter_table();
  global_.resize(t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    global_[i] = t[i].default_value;
    field_[i].resize(0);
  }
  ++revision_;
  ++matrix_revision_;
}

void ParameterSet::touched(Param p) {
  ++revision_;
  if (parameter_refactors(p)) ++matrix_revision_;
}

void ParameterSet::set(Param p, double value) {
  check_parameter_value(p, value);
  global_[index(p)] = value;
  field_[index(p)].resize(0);
  touched(p);
}

void ParameterSet::set_field(Param p, const Eigen::VectorXd& values) {
  const ParameterSpec& spec = parameter_spec(p);
  const Domain domain = parameter_domain(p);
  require(domain != Domain::kGlobal, "parameter '" + spec.name + "' is global and has no per-element values");
  const std::size_t n = domain_size(domain);
  require(static_cast<std::size_t>(values.size()) == n,
          "parameter '" + spec.name + "': " + std::to_string(values.size()) + " values given, but its domain " +
              spec.domain + " has " + std::to_string(n) + " elements");
  for (Eigen::Index i = 0; i < values.size(); ++i)
    check_parameter_value(p, values[i], "[" + std::to_string(i) + "]");
  field_[index(p)] = values;
  touched(p);
}

void ParameterSet::clear_field(Param p) {
  field_[index(p)].resize(0);
  touched(p);
}

}  // namespace softdeca::sim
