// Placeholder until this command lands; replaced by its implementation.
#include "commands.h"

namespace nsg::cli {

void add_synth_command(CLI::App& parent, Context& ctx) { (void)parent; (void)ctx; }

}  // namespace nsg::cli
