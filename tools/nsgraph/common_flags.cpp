// Options every command that has them declares the same way (docs/cli.md).
#include "commands.h"

namespace nsg::cli {

CLI::Option* add_threads_option(CLI::App* cmd, int& threads, const std::string& what) {
  threads = 0;  // one default everywhere: all cores (outputs never depend on the count)
  return cmd->add_option("--threads", threads, what + ": 0 = all cores; the output does not depend on it")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
}

}  // namespace nsg::cli
