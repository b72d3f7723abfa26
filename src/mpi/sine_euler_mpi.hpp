// Sine-Euler spread over the processes of an MPI communicator: the same
// splitting, pieces and results as the model of src/models/sine_euler, with
// each process holding its run of every direction's lines (line_exchange.hpp)
// and the line flows running where the lines are.
#pragma once

#include <mpi.h>

#include <memory>

#include "../core/model.hpp"
#include "communicator.hpp"

namespace lpi {

// Collective over comm. Throws as make_sine_euler does (the same status on
// every process), LPI_ERR_INVALID when the processes pass different N.
std::unique_ptr<Model> make_sine_euler_mpi(int N, std::shared_ptr<const mpi::Communicator> comm);

// The working state of this process, in the first direction's layout, of the
// whole mode array `modes` (2 N^2 doubles) of a distributed model (a
// checkpoint's state).
std::vector<double> local_state_of_modes(const Model &model, const double *modes);

}  // namespace lpi
