// Placeholder until this command lands; replaced by its implementation.
#include "commands.h"

namespace nsg::cli {

void add_inspect_centerlines(CLI::App& parent, Context& ctx) { (void)parent; (void)ctx; }

}  // namespace nsg::cli
