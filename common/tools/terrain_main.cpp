// marsala-terrain: generate, import, inspect, render terrains; MARS and navigability from the shell.
#include <iostream>

#include "marsala/cli/terrain_cli.hpp"

int main(int argc, char** argv) { return marsala::cli::run_terrain_cli(argc, argv, std::cout, std::cerr); }
