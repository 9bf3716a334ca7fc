// Declarative options of one sub-command: "--name VALUE" options with defaults, "--flag"
// switches and positional arguments; --help text generated from the declarations.
#pragma once

#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "command.h"

namespace softdeca::cli {

// A mistake on the command line: main prints it, the command exits with status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Options {
 public:
  Options(std::string command, std::string description);
  Options& option(const std::string& name, const std::string& metavar, const std::string& help,
                  const std::string& default_value = "");
  Options& flag(const std::string& name, const std::string& help);
  Options& positional(const std::string& name, const std::string& help);

  // False when --help was asked for (the help is then printed): the command returns 0.
  // Throws UsageError on unknown options, missing values or positionals.
  bool parse(const Args& args);

  std::string text(const std::string& name) const;  // "" when not given and no default
  bool given(const std::string& name) const;
  double number(const std::string& name) const;     // throws UsageError when not a number
  long integer(const std::string& name) const;
  bool on(const std::string& flag) const;
  const std::string& arg(std::size_t i) const { return positional_values_.at(i); }
  std::string help() const;

 private:
  struct Spec {
    std::string metavar, help, default_value;
    bool is_flag = false;
  };
  std::string command_, description_;
  std::vector<std::string> order_;
  std::map<std::string, Spec> specs_;
  std::vector<std::pair<std::string, std::string>> positionals_;
  std::map<std::string, std::string> values_;
  std::vector<std::string> positional_values_;
};

}  // namespace softdeca::cli
