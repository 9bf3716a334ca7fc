// softdeca: the command line of the SoftDECA native library. `softdeca --help` lists the
// sub-commands; `softdeca <command> --help` explains one.
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <stdexcept>
#include <string>

#include "command.h"
#include "options.h"
#include "softdeca/softdeca.h"

namespace {
void usage(std::FILE* out) {
  std::fprintf(out, "usage: softdeca <command> [options]   (softdeca <command> --help for its options)\n\n"
                    "SoftDECA %s: physics-based facial animation, native tools.\n\ncommands:\n",
               softdeca_version());
  for (const auto& c : softdeca::cli::commands()) std::fprintf(out, "  %-16s %s\n", c.name, c.summary);
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::printf("softdeca %s\n", softdeca_version());
    return 0;
  }
  for (const auto& c : softdeca::cli::commands()) {
    if (std::strcmp(argv[1], c.name) != 0) continue;
    try {
      return c.run(softdeca::cli::Args(argv + 2, argv + argc));
    } catch (const softdeca::cli::UsageError& e) {
      std::fprintf(stderr, "softdeca %s: %s\n", c.name, e.what());
      return 2;
    } catch (const std::bad_alloc&) {
      // Every reader bounds what it allocates; what is left is a machine with less memory than
      // an input within those bounds needs.
      std::fprintf(stderr, "softdeca %s: error: not enough memory for this input (docs/security.md lists the sizes each "
                           "input may have)\n", c.name);
      return 1;
    } catch (const std::logic_error&) {
      // A standard library check (an index, a length) caught what no check of ours named: the
      // input is malformed in a way this version does not describe.
      std::fprintf(stderr, "softdeca %s: error: the input is malformed in a way this version cannot describe (an "
                           "internal check failed: please report it with the file)\n", c.name);
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "softdeca %s: error: %s\n", c.name, e.what());
      return 1;
    }
  }
  std::fprintf(stderr, "softdeca: unknown command '%s'\n\n", argv[1]);
  usage(stderr);
  return 2;
}
