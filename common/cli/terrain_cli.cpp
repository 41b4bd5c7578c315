#include "common/cli/terrain_cli.hpp"

#include <ostream>

namespace marsala::cli {

int run_terrain_cli(int, const char* const*, std::ostream&, std::ostream& err) {
  err << "marsala-terrain: not implemented yet\n";
  return 2;
}

}  // namespace marsala::cli
