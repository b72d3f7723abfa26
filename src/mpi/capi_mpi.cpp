// The C ABI of the MPI part (include/liepoisson_mpi.h).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../capi/handle.hpp"
#include "../core/checkpoint.hpp"
#include "../core/text.hpp"
#include "../models/sine_euler.hpp"
#include "communicator.hpp"
#include "liepoisson_mpi.h"
#include "sine_euler_mpi.hpp"

using lpi::capi::Arguments;
using lpi::capi::guarded;
using lpi::capi::require;
using lpi::capi::require_path;
using lpi::capi::Text;

namespace {

// The processes compare their arguments (as every call on a spread handle
// does, src/capi/handle.hpp) before one of them can refuse them alone.
void require_same_arguments(const lpi::mpi::Communicator &comm, const char *function, const Arguments &arguments) {
    comm.require_same(static_cast<long long>(arguments.fingerprint(function)), "arguments to this call (or made different calls)");
}

// Made from a callback of a system, a collective call on comm would leave
// the processes where the callback did not fail waiting.
void refuse_from_a_callback() {
    if (lpi::capi::calls_in_progress() > 1) lpi::fail(LPI_ERR_INVALID, lpi::capi::kSpreadFromCallback);
}

// A refused file's path leads the message, as in lpi_load (I/O errors name
// it already).
template <class Action>
void naming_path(const char *path, Action &&action) {
    try {
        action();
    } catch (const lpi::Error &e) {
        if (e.status() != LPI_ERR_FORMAT && e.status() != LPI_ERR_UNSUPPORTED) throw;
        lpi::fail(e.status(), lpi::quoted(path) + ": " + e.what());
    }
}

}  // namespace

extern "C" {

LPI_API int lpi_sine_euler_create_mpi(lpi_system **out, int32_t N, MPI_Comm comm) {
    if (out) *out = nullptr;
    return guarded(nullptr, "lpi_sine_euler_create_mpi", [&] {
        refuse_from_a_callback();
        auto communicator = lpi::mpi::Communicator::duplicate(comm);
        // N: compared by the model, named.
        require_same_arguments(*communicator, "lpi_sine_euler_create_mpi", Arguments(out));
        require(out, "out");
        std::unique_ptr<lpi::Model> model = lpi::make_sine_euler_mpi(N, communicator);
        // The handle's states are allocated here: one process short of memory
        // fails the call on all of them (it failed alone, the others' handles
        // left waiting in their next collective).
        std::unique_ptr<lpi_system> handle;
        communicator->agree([&] { handle = std::make_unique<lpi_system>(std::move(model)); });
        *out = handle.release();
    });
}

LPI_API int lpi_load_mpi(lpi_system **out, const char *path, MPI_Comm comm) {
    if (out) *out = nullptr;
    return guarded(nullptr, "lpi_load_mpi", [&] {
        refuse_from_a_callback();
        const auto communicator = lpi::mpi::Communicator::duplicate(comm);
        const lpi::mpi::Communicator &reader = *communicator;
        require_same_arguments(reader, "lpi_load_mpi", Arguments(out, Text{path}));
        require(out, "out");
        require_path(path);
        // Rank 0 reads; every process decodes the same bytes. Whatever a
        // process allocates between two collectives is agreed on: one
        // process short of memory fails the call on all of them instead of
        // leaving the others waiting in the next collective.
        std::vector<unsigned char> bytes;
        double size = 0.0;
        reader.on_root([&] {
            naming_path(path, [&] { bytes = lpi::read_checkpoint_file(path); });
            size = static_cast<double>(bytes.size());
        });
        reader.broadcast(&size, 1);
        reader.agree([&] { bytes.resize(static_cast<std::size_t>(size)); });
        reader.broadcast(bytes.data(), bytes.size());
        lpi::Checkpoint cp;
        int N = 0;
        std::string split;
        std::optional<lpi::sine_euler::Hamiltonian> hamiltonian;
        reader.agree([&] {
            naming_path(path, [&] { cp = lpi::decode_checkpoint(bytes.data(), bytes.size()); });
            std::vector<unsigned char>().swap(bytes);
            if (std::string(cp.model->kind()) != "sine-euler")
                lpi::fail(LPI_ERR_UNSUPPORTED, lpi::quoted(path) + " holds a " +
                                                   cp.model->kind() +
                                                   " system; only sine-euler is spread over processes");
            const auto &whole = static_cast<const lpi::SineEulerModel &>(*cp.model);
            N = whole.truncation();
            split = whole.split();
            hamiltonian.emplace(whole.hamiltonian());
            cp.model.reset();  // the whole field is not kept
        });
        std::unique_ptr<lpi::Model> model = lpi::make_sine_euler_mpi(N, communicator);
        model->set_split(split);
        static_cast<lpi::SineEulerModel &>(*model).set_hamiltonian(std::move(*hamiltonian));
        hamiltonian.reset();
        std::unique_ptr<lpi_system> handle;
        reader.agree([&] {
            cp.state = lpi::local_state_of_modes(*model, cp.state.data());
            handle = std::make_unique<lpi_system>(std::move(model));
        });
        // Its calls agree on each outcome (an action makes no collective).
        naming_path(path, [&] { lpi::restore_checkpoint(handle->system, cp); });
        *out = handle.release();
    });
}

}  // extern "C"
