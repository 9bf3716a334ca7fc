#include "options.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace softdeca::cli {

Options::Options(std::string command, std::string description)
    : command_(std::move(command)), description_(std::move(description)) {
  flag("--help", "show this help and exit");
}

Options& Options::option(const std::string& name, const std::string& metavar, const std::string& help,
                         const std::string& default_value) {
  order_.push_back(name);
  specs_[name] = Spec{metavar, help, default_value, false};
  return *this;
}

Options& Options::flag(const std::string& name, const std::string& help) {
  order_.push_back(name);
  specs_[name] = Spec{"", help, "", true};
  return *this;
}

Options& Options::positional(const std::string& name, const std::string& help) {
  positionals_.emplace_back(name, help);
  return *this;
}

bool Options::parse(const Args& args) {
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::fputs(help().c_str(), stdout);
      return false;
    }
    if (a.size() > 2 && a.compare(0, 2, "--") == 0) {
      std::string name = a, value;
      const std::size_t eq = a.find('=');
      if (eq != std::string::npos) {
        name = a.substr(0, eq);
        value = a.substr(eq + 1);
      }
      const auto it = specs_.find(name);
      if (it == specs_.end()) throw UsageError("unknown option " + name + " (see --help)");
      if (it->second.is_flag) {
        if (eq != std::string::npos) throw UsageError(name + " takes no value");
        values_[name] = "1";
        continue;
      }
      if (eq == std::string::npos) {
        if (i + 1 >= args.size()) throw UsageError(name + " needs a value " + it->second.metavar);
        value = args[++i];
      }
      values_[name] = value;
      continue;
    }
    positional_values_.push_back(a);
  }
  if (positional_values_.size() < positionals_.size())
    throw UsageError("missing " + positionals_[positional_values_.size()].first + " (see --help)");
  if (positional_values_.size() > positionals_.size())
    throw UsageError("unexpected argument '" + positional_values_[positionals_.size()] + "'");
  return true;
}

std::string Options::text(const std::string& name) const {
  const auto v = values_.find(name);
  if (v != values_.end()) return v->second;
  const auto s = specs_.find(name);
  return s == specs_.end() ? "" : s->second.default_value;
}

bool Options::given(const std::string& name) const { return values_.count(name) > 0; }

double Options::number(const std::string& name) const {
  const std::string t = text(name);
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (t.empty() || *end != '\0' || !std::isfinite(v)) throw UsageError(name + " needs a number, not '" + t + "'");
  return v;
}

long Options::integer(const std::string& name) const {
  const std::string t = text(name);
  char* end = nullptr;
  const long v = std::strtol(t.c_str(), &end, 10);
  if (t.empty() || *end != '\0') throw UsageError(name + " needs a whole number, not '" + t + "'");
  return v;
}

bool Options::on(const std::string& flag) const { return values_.count(flag) > 0; }

std::string Options::help() const {
  std::string out = "usage: softdeca " + command_ + " [options]";
  for (const auto& [name, _] : positionals_) out += " " + name;
  out += "\n\n" + description_ + "\n";
  if (!positionals_.empty()) {
    out += "\narguments:\n";
    for (const auto& [name, h] : positionals_) {
      char line[512];
      std::snprintf(line, sizeof line, "  %-24s %s\n", name.c_str(), h.c_str());
      out += line;
    }
  }
  out += "\noptions:\n";
  for (const std::string& name : order_) {
    const Spec& s = specs_.at(name);
    const std::string left = s.is_flag ? name : name + " " + s.metavar;
    std::string right = s.help;
    if (!s.default_value.empty()) right += " (default " + s.default_value + ")";
    char line[1024];
    std::snprintf(line, sizeof line, "  %-24s %s\n", left.c_str(), right.c_str());
    out += line;
  }
  return out;
}

}  // namespace softdeca::cli
