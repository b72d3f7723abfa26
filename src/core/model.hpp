// A Model is one Lie-Poisson system together with a choice of Hamiltonian
// split: it knows its pieces' exact flows, its energy and its Casimirs. It
// never owns the state; the System does (so rollback is one copy).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "action_ref.hpp"

namespace lpi {

class Model {
public:
    virtual ~Model() = default;

    // Short kind name ("rigid-body"), used in messages and checkpoints.
    virtual const char *kind() const = 0;

    // Public coordinates (what lpi_get_state returns).
    virtual std::size_t dim() const = 0;

    // Working layout that the flows act on. Models whose natural layout
    // differs from the public coordinates (sine-Euler keeps full complex
    // modes) override these; the default is the identity.
    virtual std::size_t state_size() const { return dim(); }
    virtual void to_public(const double *state, double *x) const;
    // Validates x (throws lpi::Error) and writes the working layout.
    virtual void from_public(const double *x, double *state) const;

    // Hamiltonian split currently in use.
    virtual std::vector<std::string> split_names() const = 0;  // first = default
    virtual void set_split(const std::string &name) = 0;        // throws if unknown
    virtual std::string split() const = 0;
    virtual std::size_t piece_count() const = 0;

    // Exact flow of piece k for time t, in place on the working layout.
    // Flows may leave out of date the part of the state that follows from
    // the rest (sine-Euler: the conjugate half of the modes), which they
    // never read, and may work on a copy of their own (sine-Euler: the modes
    // transposed); settle writes both back. The integrator settles the state
    // before anything but a flow reads or copies it; prepare_step drops a
    // copy that a failed step left behind.
    virtual void flow(std::size_t piece, double t, double *state) = 0;
    virtual void settle(double * /*state*/) {}

    virtual double energy(const double *state) const = 0;
    virtual std::size_t casimir_count() const = 0;
    virtual void casimirs(const double *state, double *out) const = 0;

    // The full vector field J(x) grad H(x) in the working layout: what the
    // baselines (src/baselines) integrate.
    virtual void vector_field(const double *state, double *rate) const = 0;

    // Sets up what the flows of a step need (plans, buffers) before the
    // first: System::step calls it where a failure on one process of a
    // spread model is agreed on by every process, while inside a flow it
    // would leave the others waiting in a collective. Nothing by default.
    virtual void prepare_step() {}

    // Threads used inside one flow. The default integrates on one thread:
    // n = 1 is accepted, n > 1 throws LPI_ERR_UNSUPPORTED.
    virtual void set_threads(int n);

    // What a checkpoint stores to rebuild this model: its parameters, which
    // the CheckpointKind of its kind (checkpoint.hpp, listed in
    // src/registry.cpp) turns back into the model. The default refuses with
    // LPI_ERR_UNSUPPORTED.
    virtual std::vector<double> checkpoint_parameters() const;

    // ---- models spread over processes (sine-Euler on MPI) ----------------
    // Their working state is this process's part of the field, and every call
    // on them is collective: each process makes the same calls in the same
    // order. The defaults describe a model held whole by one process.
    virtual bool distributed() const { return false; }
    // Whether the working state is finite: the same answer on every process.
    virtual bool finite(const double *state) const;
    // The working state of the whole model, as a model of its kind held by
    // one process stores it (what a checkpoint saves), on every process.
    virtual std::vector<double> whole_state(const double *state) const;
    // Runs action on one process (a file written once) and gives its outcome,
    // a return or an lpi::Error, to every process.
    virtual void on_one_process(ActionRef action) const { action(); }
    // Whether `value` holds on any process (an observer that stops the run
    // on one process stops it on all).
    virtual bool on_any_process(bool value) const { return value; }
    // Runs action on every process; when it throws on any of them, every
    // process throws the status and message of the lowest such rank (a
    // check whose answer may differ between processes, such as a thread
    // count bounded by each process's processors).
    virtual void agree_on_every_process(ActionRef action) const { action(); }
    // Throws LPI_ERR_INVALID on every process when the processes passed
    // different bytes (`what`, named in the message), before anything reads
    // them otherwise: a value refused on one process alone would leave the
    // others waiting in a collective. Nothing for a model of one process.
    // `what` is a C string: a std::string made for the call could fail to
    // allocate on one process alone, before the collective.
    virtual void require_same_on_every_process(const void *bytes, std::size_t size, const char *what) const {
        (void)bytes, (void)size, (void)what;
    }
};

}  // namespace lpi

namespace lpi {

// The named Hamiltonian splits a model offers and which one is in use.
class SplitChoice {
public:
    explicit SplitChoice(std::vector<std::string> names) : names_(std::move(names)) {}
    const std::vector<std::string> &names() const { return names_; }
    const std::string &current() const { return names_[index_]; }
    std::size_t index() const { return index_; }
    void select(const std::string &name, const char *model_kind);  // throws if unknown

private:
    std::vector<std::string> names_;
    std::size_t index_ = 0;
};

}  // namespace lpi
