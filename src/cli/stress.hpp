// lpi stress: stiff and extreme cases against every applicable method.
#pragma once

namespace lpi_cli {

// Runs the matrix of stress cases (quick: a few seconds; otherwise minutes)
// and prints one line per case, step and method. Returns 0 when every
// property that must hold held, 1 otherwise.
int stress_command(int argc, char **argv);

}  // namespace lpi_cli
