// A reference to a callable taking and returning nothing, made without
// allocating. std::function allocates for a lambda that captures more than
// two references; on a model spread over processes, an agreement whose
// action could not be wrapped would fail on one process before it begins,
// leaving the others waiting in its collective.
#pragma once

#include <memory>
#include <type_traits>

namespace lpi {

class ActionRef {
public:
    // The callable must outlive the reference: pass a lambda straight to a
    // function taking an ActionRef (it lives until the call returns).
    template <class F, class = std::enable_if_t<!std::is_same_v<std::decay_t<F>, ActionRef>>>
    ActionRef(F &&f) noexcept  // NOLINT(google-explicit-constructor): made from lambdas
        : object_(const_cast<void *>(static_cast<const void *>(std::addressof(f)))),
          call_([](void *object) { (*static_cast<std::remove_reference_t<F> *>(object))(); }) {}
    void operator()() const { call_(object_); }

private:
    void *object_;
    void (*call_)(void *);
};

}  // namespace lpi
