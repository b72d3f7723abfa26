// `lpi run`: integrate one scene with the user's options, writing diagnostics
// as CSV and, for sine-Euler, vorticity snapshots as PNG.
#pragma once

namespace lpi_cli {

int run_command(int argc, char **argv);

}  // namespace lpi_cli
