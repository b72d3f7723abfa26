"""
    LiePoisson

Julia binding of libliepoisson: explicit, Casimir-preserving integration of
Lie-Poisson systems. Two layers:

* `LiePoisson.C`: one `ccall` wrapper per public C function, same name and
  arguments as in `liepoisson.h` (returns the C result, e.g. a status).
* the high-level API: `RigidBody`, `Pendulum`, `Generic`, `Moments`,
  `SineEuler`, `step!`, `state`, `set_state!`, `energy`, `casimirs`, ...
  Failures throw `LiePoissonError` (status, status name, message).

The library is opened when the module is loaded: the path in the environment
variable `LIEPOISSON_LIBRARY`, else `libliepoisson.so.0` from the system's
library path.
"""
module LiePoisson

using Libdl

const _lib = Ref{Ptr{Cvoid}}(C_NULL)

function __init__()
    path = get(ENV, "LIEPOISSON_LIBRARY", "")
    _lib[] = Libdl.dlopen(isempty(path) ? "libliepoisson.so.0" : path)
end

_sym(name::Symbol) = Libdl.dlsym(_lib[], name)

# ---- the C functions, one wrapper each ----------------------------------------
module C
import ..LiePoisson: _sym
const Sys = Ptr{Cvoid}   # lpi_system *

# version, status codes, methods
lpi_version_string() = ccall(_sym(:lpi_version_string), Cstring, ())
lpi_version_number() = ccall(_sym(:lpi_version_number), Cint, ())
lpi_status_name(status) = ccall(_sym(:lpi_status_name), Cstring, (Cint,), status)
lpi_status_message(status) = ccall(_sym(:lpi_status_message), Cstring, (Cint,), status)
lpi_method_count() = ccall(_sym(:lpi_method_count), Cint, ())
lpi_method_name(i) = ccall(_sym(:lpi_method_name), Ptr{Cchar}, (Cint,), i)
lpi_method_order(i) = ccall(_sym(:lpi_method_order), Cint, (Cint,), i)
lpi_method_is_poisson(i) = ccall(_sym(:lpi_method_is_poisson), Cint, (Cint,), i)
lpi_method_stages(i) = ccall(_sym(:lpi_method_stages), Cint, (Cint,), i)
lpi_method_reference(i) = ccall(_sym(:lpi_method_reference), Ptr{Cchar}, (Cint,), i)
# systems
lpi_rigid_body_create(out, I1, I2, I3) =
    ccall(_sym(:lpi_rigid_body_create), Cint, (Ptr{Sys}, Cdouble, Cdouble, Cdouble), out, I1, I2, I3)
lpi_rigid_body_exact(sys, t, out) =
    ccall(_sym(:lpi_rigid_body_exact), Cint, (Sys, Cdouble, Ptr{Cdouble}), sys, t, out)
lpi_pendulum_create(out) = ccall(_sym(:lpi_pendulum_create), Cint, (Ptr{Sys},), out)
lpi_destroy(sys) = ccall(_sym(:lpi_destroy), Cint, (Sys,), sys)
lpi_set_method(sys, name) = ccall(_sym(:lpi_set_method), Cint, (Sys, Cstring), sys, name)
lpi_set_split(sys, name) = ccall(_sym(:lpi_set_split), Cint, (Sys, Cstring), sys, name)
lpi_kind(sys) = ccall(_sym(:lpi_kind), Cstring, (Sys,), sys)
lpi_get_method(sys) = ccall(_sym(:lpi_get_method), Cstring, (Sys,), sys)
lpi_get_split(sys) = ccall(_sym(:lpi_get_split), Cstring, (Sys,), sys)
lpi_dim(sys) = ccall(_sym(:lpi_dim), Csize_t, (Sys,), sys)
lpi_set_state(sys, x, n) = ccall(_sym(:lpi_set_state), Cint, (Sys, Ptr{Cdouble}, Csize_t), sys, x, n)
lpi_get_state(sys, x, n) = ccall(_sym(:lpi_get_state), Cint, (Sys, Ptr{Cdouble}, Csize_t), sys, x, n)
lpi_step(sys, dt, nsteps) = ccall(_sym(:lpi_step), Cint, (Sys, Cdouble, Int64), sys, dt, nsteps)
# fn: a @cfunction pointer of Cint (Ptr{Cvoid}, Int64, Cdouble, Ptr{Cvoid}), or C_NULL to remove.
lpi_set_observer(sys, every, fn, user) =
    ccall(_sym(:lpi_set_observer), Cint, (Sys, Int64, Ptr{Cvoid}, Ptr{Cvoid}), sys, every, fn, user)
lpi_time(sys) = ccall(_sym(:lpi_time), Cdouble, (Sys,), sys)
lpi_energy(sys, out) = ccall(_sym(:lpi_energy), Cint, (Sys, Ptr{Cdouble}), sys, out)
lpi_casimir_count(sys) = ccall(_sym(:lpi_casimir_count), Csize_t, (Sys,), sys)
lpi_casimirs(sys, out, n) = ccall(_sym(:lpi_casimirs), Cint, (Sys, Ptr{Cdouble}, Csize_t), sys, out, n)
lpi_last_error(sys) = ccall(_sym(:lpi_last_error), Cstring, (Sys,), sys)
# composition methods, implicit baselines
lpi_set_composition(sys, n, gammas) =
    ccall(_sym(:lpi_set_composition), Cint, (Sys, Csize_t, Ptr{Cdouble}), sys, n, gammas)
lpi_flows_per_step(sys, out) = ccall(_sym(:lpi_flows_per_step), Cint, (Sys, Ptr{Csize_t}), sys, out)
lpi_set_implicit_options(sys, tolerance, max_iterations) =
    ccall(_sym(:lpi_set_implicit_options), Cint, (Sys, Cdouble, Int32), sys, tolerance, max_iterations)
# generic systems and the moment algebra
lpi_generic_create(out, dim, nnz, i, j, k, c) =
    ccall(_sym(:lpi_generic_create), Cint,
          (Ptr{Sys}, Csize_t, Csize_t, Ptr{Int32}, Ptr{Int32}, Ptr{Int32}, Ptr{Cdouble}),
          out, dim, nnz, i, j, k, c)
lpi_add_piece(sys, n, indices, grad, energy, user) =
    ccall(_sym(:lpi_add_piece), Cint, (Sys, Csize_t, Ptr{Int32}, Ptr{Cvoid}, Ptr{Cvoid}, Ptr{Cvoid}),
          sys, n, indices, grad, energy, user)
lpi_add_casimir(sys, fn, user) =
    ccall(_sym(:lpi_add_casimir), Cint, (Sys, Ptr{Cvoid}, Ptr{Cvoid}), sys, fn, user)
lpi_poisson_rank(sys, x, n, rank) =
    ccall(_sym(:lpi_poisson_rank), Cint, (Sys, Ptr{Cdouble}, Csize_t, Ptr{Csize_t}), sys, x, n, rank)
lpi_moments_create(out) = ccall(_sym(:lpi_moments_create), Cint, (Ptr{Sys},), out)
lpi_moments_add_product_piece(sys, h, dh, user) =
    ccall(_sym(:lpi_moments_add_product_piece), Cint, (Sys, Ptr{Cvoid}, Ptr{Cvoid}, Ptr{Cvoid}),
          sys, h, dh, user)
# sine-Euler, threads, FFTW wisdom
lpi_sine_euler_create(out, N) = ccall(_sym(:lpi_sine_euler_create), Cint, (Ptr{Sys}, Int32), out, N)
lpi_sine_euler_size(sys, N) = ccall(_sym(:lpi_sine_euler_size), Cint, (Sys, Ptr{Int32}), sys, N)
lpi_sine_euler_set_modes(sys, re_im, n) =
    ccall(_sym(:lpi_sine_euler_set_modes), Cint, (Sys, Ptr{Cdouble}, Csize_t), sys, re_im, n)
lpi_sine_euler_get_modes(sys, re_im, n) =
    ccall(_sym(:lpi_sine_euler_get_modes), Cint, (Sys, Ptr{Cdouble}, Csize_t), sys, re_im, n)
lpi_sine_euler_set_grid(sys, w, n) =
    ccall(_sym(:lpi_sine_euler_set_grid), Cint, (Sys, Ptr{Cdouble}, Csize_t), sys, w, n)
lpi_sine_euler_get_grid(sys, w, n) =
    ccall(_sym(:lpi_sine_euler_get_grid), Cint, (Sys, Ptr{Cdouble}, Csize_t), sys, w, n)
lpi_sine_euler_enstrophy(sys, out) =
    ccall(_sym(:lpi_sine_euler_enstrophy), Cint, (Sys, Ptr{Cdouble}), sys, out)
lpi_sine_euler_casimir_traces(sys, kmax, out) =
    ccall(_sym(:lpi_sine_euler_casimir_traces), Cint, (Sys, Int32, Ptr{Cdouble}), sys, kmax, out)
lpi_sine_euler_fft_floor(sys, nsteps, seconds, transforms) =
    ccall(_sym(:lpi_sine_euler_fft_floor), Cint, (Sys, Int64, Ptr{Cdouble}, Ptr{Cdouble}),
          sys, nsteps, seconds, transforms)
lpi_sine_euler_set_planning(sys, rigor) =
    ccall(_sym(:lpi_sine_euler_set_planning), Cint, (Sys, Cstring), sys, rigor)
lpi_sine_euler_get_planning(sys, rigor) =
    ccall(_sym(:lpi_sine_euler_get_planning), Cint, (Sys, Ptr{Cstring}), sys, rigor)
lpi_sine_euler_set_hamiltonian(sys, lambda, n_lambda, f, n_f) =
    ccall(_sym(:lpi_sine_euler_set_hamiltonian), Cint, (Sys, Ptr{Cdouble}, Csize_t, Ptr{Cdouble}, Csize_t),
          sys, lambda, n_lambda, f, n_f)
lpi_sine_euler_get_stream(sys, psi, n) =
    ccall(_sym(:lpi_sine_euler_get_stream), Cint, (Sys, Ptr{Cdouble}, Csize_t), sys, psi, n)
lpi_sine_euler_spectrum(sys, energy, enstrophy, n, shells) =
    ccall(_sym(:lpi_sine_euler_spectrum), Cint, (Sys, Ptr{Cdouble}, Ptr{Cdouble}, Csize_t, Ptr{Csize_t}),
          sys, energy, enstrophy, n, shells)
lpi_set_threads(sys, n) = ccall(_sym(:lpi_set_threads), Cint, (Sys, Int32), sys, n)
lpi_fftw_wisdom_import_file(path) = ccall(_sym(:lpi_fftw_wisdom_import_file), Cint, (Cstring,), path)
lpi_fftw_wisdom_export_file(path) = ccall(_sym(:lpi_fftw_wisdom_export_file), Cint, (Cstring,), path)
lpi_fftw_wisdom_import_string(w) = ccall(_sym(:lpi_fftw_wisdom_import_string), Cint, (Cstring,), w)
lpi_fftw_wisdom_export_string(buf, size, length) =
    ccall(_sym(:lpi_fftw_wisdom_export_string), Cint, (Ptr{UInt8}, Csize_t, Ptr{Csize_t}),
          buf, size, length)
lpi_save(sys, path) = ccall(_sym(:lpi_save), Cint, (Sys, Cstring), sys, path)
lpi_load(out, path) = ccall(_sym(:lpi_load), Cint, (Ptr{Sys}, Cstring), out, path)
lpi_save_buffer(sys, buf, capacity, size) =
    ccall(_sym(:lpi_save_buffer), Cint, (Sys, Ptr{UInt8}, Csize_t, Ptr{Csize_t}), sys, buf, capacity, size)
lpi_load_buffer(out, buf, size) =
    ccall(_sym(:lpi_load_buffer), Cint, (Ptr{Sys}, Ptr{UInt8}, Csize_t), out, buf, size)
end # module C

# ---- errors --------------------------------------------------------------------

"""A failed call: `status` (negative code), `name` ("LPI_ERR_SIZE"), `message`.
Non-negative statuses (`LPI_OK`, and `LPI_STOPPED` = 1 from `lpi_step`) are not failures."""
struct LiePoissonError <: Exception
    status::Int
    name::String
    message::String
end
Base.showerror(io::IO, e::LiePoissonError) = print(io, e.name, ": ", e.message)

status_name(status::Integer) = unsafe_string(C.lpi_status_name(status))
status_message(status::Integer) = unsafe_string(C.lpi_status_message(status))
version() = VersionNumber(unsafe_string(C.lpi_version_string()))
# MAJOR * 10000 + MINOR * 100 + PATCH of the library that runs.
version_number() = Int(C.lpi_version_number())

function _check(status, handle::Ptr{Cvoid} = C_NULL, cause = nothing)
    status >= 0 && return nothing
    # Refused because another thread is inside a call on the handle: the
    # message is this thread's (the handle's is that thread's to write).
    message = status == -13 ? unsafe_string(C.lpi_last_error(C_NULL)) : ""  # -13: LPI_ERR_BUSY (ABI)
    occursin("another thread is inside a call on this handle", message) ||
        (message = unsafe_string(C.lpi_last_error(handle)))
    # Julia has no exception chaining: a callback's exception joins the message.
    cause === nothing || (message *= " (callback threw: " * sprint(showerror, cause) * ")")
    throw(LiePoissonError(status, status_name(status), message))
end

_cstring_or_empty(p::Ptr{Cchar}) = p == C_NULL ? "" : unsafe_string(p)

"""All registered methods as named tuples (name, order, stages, reference, is_poisson)."""
function methods()
    [(name = _cstring_or_empty(C.lpi_method_name(i)), order = Int(C.lpi_method_order(i)),
      stages = Int(C.lpi_method_stages(i)), reference = _cstring_or_empty(C.lpi_method_reference(i)),
      is_poisson = C.lpi_method_is_poisson(i) == 1) for i in 0:C.lpi_method_count()-1]
end

# ---- systems --------------------------------------------------------------------

# Callbacks: one C trampoline per signature; `user` points at a _Callback that
# holds the Julia function and records an exception instead of unwinding into C.
mutable struct _Callback
    f::Any
    owner::Any         # the System's pending-exception list
end

"""A handle to an integrated system; released by `close` or the finaliser."""
mutable struct System
    handle::Ptr{Cvoid}
    callbacks::Vector{_Callback}
    pending::Vector{Any}
    function System(create::Function)
        out = Ref{Ptr{Cvoid}}(C_NULL)
        _check(create(out))
        sys = new(out[], _Callback[], Any[])
        finalizer(close, sys)
    end
end

function Base.close(sys::System)
    if sys.handle != C_NULL
        # LPI_ERR_BUSY from one of the system's own callbacks: nothing freed.
        _check(C.lpi_destroy(sys.handle), sys.handle)
        sys.handle = C_NULL
    end
    nothing
end

function _h(sys::System)
    sys.handle == C_NULL && throw(ArgumentError("operation on a closed liepoisson system"))
    sys.handle
end

# Calls f(handle) and throws on failure (with a callback's exception attached).
function _call(f, sys::System)
    empty!(sys.pending)
    status = GC.@preserve sys f(_h(sys))
    if status < 0
        cause = isempty(sys.pending) ? nothing : sys.pending[1]
        empty!(sys.pending)
        _check(status, sys.handle, cause)
    end
    nothing
end

RigidBody(I1, I2, I3) = System(out -> C.lpi_rigid_body_create(out, I1, I2, I3))
Pendulum() = System(out -> C.lpi_pendulum_create(out))
Moments() = System(out -> C.lpi_moments_create(out))
SineEuler(N::Integer) = System(out -> C.lpi_sine_euler_create(out, N))

"""save(sys, path): writes a checkpoint atomically; `load(path)` resumes it bit for bit."""
save(sys::System, path::AbstractString) = _call(h -> C.lpi_save(h, path), sys)
load(path::AbstractString) = System(out -> C.lpi_load(out, path))
function save_bytes(sys::System)
    size = Ref{Csize_t}(0)
    _call(h -> C.lpi_save_buffer(h, C_NULL, 0, size), sys)
    buf = Vector{UInt8}(undef, size[])
    _call(h -> C.lpi_save_buffer(h, buf, length(buf), size), sys)
    buf
end
load_bytes(buf::Vector{UInt8}) = System(out -> C.lpi_load_buffer(out, buf, length(buf)))

"""Generic(dim, brackets): {x_i, x_j} = sum c x_k over (i, j, k, c), 0-based."""
function Generic(dim::Integer, brackets = Tuple{Int,Int,Int,Float64}[])
    i = Int32[b[1] for b in brackets]; j = Int32[b[2] for b in brackets]
    k = Int32[b[3] for b in brackets]; c = Float64[b[4] for b in brackets]
    System(out -> C.lpi_generic_create(out, dim, length(c), i, j, k, c))
end

# The system's kind ("rigid-body", ..., "sine-euler"), method and split names.
# The strings belong to the handle: sys is kept alive (its finalizer would
# free them) until they are copied.
kind(sys::System) = GC.@preserve sys unsafe_string(C.lpi_kind(_h(sys)))
method_name(sys::System) = GC.@preserve sys unsafe_string(C.lpi_get_method(_h(sys)))
split_name(sys::System) = GC.@preserve sys unsafe_string(C.lpi_get_split(_h(sys)))
set_method!(sys::System, name::AbstractString) = _call(h -> C.lpi_set_method(h, name), sys)
set_split!(sys::System, name::AbstractString) = _call(h -> C.lpi_set_split(h, name), sys)
set_composition!(sys::System, gammas::AbstractVector{<:Real}) =
    (g = Vector{Float64}(gammas); _call(h -> C.lpi_set_composition(h, length(g), g), sys))
function flows_per_step(sys::System)
    out = Ref{Csize_t}(0); _call(h -> C.lpi_flows_per_step(h, out), sys); Int(out[])
end
set_implicit_options!(sys::System; tolerance = 1e-13, max_iterations = 100) =
    _call(h -> C.lpi_set_implicit_options(h, tolerance, max_iterations), sys)
set_threads!(sys::System, n::Integer) = _call(h -> C.lpi_set_threads(h, n), sys)

dim(sys::System) = Int(C.lpi_dim(_h(sys)))
function state(sys::System)
    x = Vector{Float64}(undef, dim(sys)); _call(h -> C.lpi_get_state(h, x, length(x)), sys); x
end
function set_state!(sys::System, x::AbstractVector{<:Real})
    v = Vector{Float64}(x)  # no copy when x already is a Vector{Float64}
    _call(h -> C.lpi_set_state(h, v, length(v)), sys)
end
step!(sys::System, dt::Real, nsteps::Integer = 1) = _call(h -> C.lpi_step(h, dt, nsteps), sys)
Base.time(sys::System) = C.lpi_time(_h(sys))
energy(sys::System) = (out = Ref{Float64}(0.0); _call(h -> C.lpi_energy(h, out), sys); out[])
casimir_count(sys::System) = Int(C.lpi_casimir_count(_h(sys)))
function casimirs(sys::System)
    out = Vector{Float64}(undef, casimir_count(sys))
    _call(h -> C.lpi_casimirs(h, out, length(out)), sys); out
end
last_error(sys::System) = GC.@preserve sys unsafe_string(C.lpi_last_error(_h(sys)))
function exact(sys::System, t::Real)
    out = Vector{Float64}(undef, 3); _call(h -> C.lpi_rigid_body_exact(h, t, out), sys); out
end
function poisson_rank(sys::System, x::AbstractVector{<:Real} = state(sys))
    v = Vector{Float64}(x); out = Ref{Csize_t}(0)
    _call(h -> C.lpi_poisson_rank(h, v, length(v), out), sys); Int(out[])
end

function _vector_trampoline(n::Csize_t, x::Ptr{Cdouble}, out::Ptr{Cdouble}, user::Ptr{Cvoid})::Cint
    cb = unsafe_pointer_to_objref(user)::_Callback
    try
        g = cb.f(copy(unsafe_wrap(Array, x, n)))
        length(g) == n || error("gradient returned $(length(g)) values for $n indices")
        for q in 1:n
            unsafe_store!(out, Float64(g[q]), q)
        end
        return Cint(0)
    catch e
        isempty(cb.owner) && push!(cb.owner, e)
        return Cint(1)
    end
end
function _scalar_of_vector_trampoline(n::Csize_t, x::Ptr{Cdouble}, out::Ptr{Cdouble},
                                      user::Ptr{Cvoid})::Cint
    cb = unsafe_pointer_to_objref(user)::_Callback
    try
        unsafe_store!(out, Float64(cb.f(copy(unsafe_wrap(Array, x, n)))))
        return Cint(0)
    catch e
        isempty(cb.owner) && push!(cb.owner, e)
        return Cint(1)
    end
end
function _scalar_trampoline(u::Cdouble, out::Ptr{Cdouble}, user::Ptr{Cvoid})::Cint
    cb = unsafe_pointer_to_objref(user)::_Callback
    try
        unsafe_store!(out, Float64(cb.f(u)))
        return Cint(0)
    catch e
        isempty(cb.owner) && push!(cb.owner, e)
        return Cint(1)
    end
end

_vector_ptr() = @cfunction(_vector_trampoline, Cint, (Csize_t, Ptr{Cdouble}, Ptr{Cdouble}, Ptr{Cvoid}))
_scalar_of_vector_ptr() =
    @cfunction(_scalar_of_vector_trampoline, Cint, (Csize_t, Ptr{Cdouble}, Ptr{Cdouble}, Ptr{Cvoid}))
_scalar_ptr() = @cfunction(_scalar_trampoline, Cint, (Cdouble, Ptr{Cdouble}, Ptr{Cvoid}))

function _keep!(sys::System, f)
    cb = _Callback(f, sys.pending)
    push!(sys.callbacks, cb)   # alive as long as the system
    cb
end

# A callback must be callable: C is handed a trampoline that always exists,
# so `nothing` or a number would fail only at the first step.
function _callable(f, what)
    # Base's: this module's own `methods()` (the composition methods) hides it.
    (f isa Function || !isempty(Base.methods(f))) ||
        throw(ArgumentError("$what must be callable, not $(typeof(f))"))
    f
end

"""add_piece!(sys, indices, gradient, energy): the piece on the 0-based abelian set
`indices`; gradient(x_sigma) returns n values and energy(x_sigma) a number. The
gradient and energy share one user pointer each: two pieces of state are kept."""
function add_piece!(sys::System, indices::AbstractVector{<:Integer}, gradient, energy)
    _callable(gradient, "gradient"); _callable(energy, "energy")
    idx = Vector{Int32}(indices)
    g = _keep!(sys, gradient); e = _keep!(sys, energy)
    # The C function takes one user pointer for both callbacks: a pair dispatches.
    pair = _keep!(sys, (g, e))
    _call(h -> C.lpi_add_piece(h, length(idx), idx, _pair_grad_ptr(), _pair_energy_ptr(),
                               pointer_from_objref(pair)), sys)
end
function _pair_grad(n::Csize_t, x::Ptr{Cdouble}, out::Ptr{Cdouble}, user::Ptr{Cvoid})::Cint
    g, _ = (unsafe_pointer_to_objref(user)::_Callback).f
    _vector_trampoline(n, x, out, pointer_from_objref(g))
end
function _pair_energy(n::Csize_t, x::Ptr{Cdouble}, out::Ptr{Cdouble}, user::Ptr{Cvoid})::Cint
    _, e = (unsafe_pointer_to_objref(user)::_Callback).f
    _scalar_of_vector_trampoline(n, x, out, pointer_from_objref(e))
end
_pair_grad_ptr() = @cfunction(_pair_grad, Cint, (Csize_t, Ptr{Cdouble}, Ptr{Cdouble}, Ptr{Cvoid}))
_pair_energy_ptr() = @cfunction(_pair_energy, Cint, (Csize_t, Ptr{Cdouble}, Ptr{Cdouble}, Ptr{Cvoid}))

"""add_casimir!(sys, f): declares the Casimir f(x) of the full state."""
function add_casimir!(sys::System, f)
    _callable(f, "the Casimir")
    cb = _keep!(sys, f)
    _call(h -> C.lpi_add_casimir(h, _scalar_of_vector_ptr(), pointer_from_objref(cb)), sys)
end

"""add_product_piece!(sys, H, dH): the moment piece H(x1 x3) with H'(u) = dH(u)."""
function add_product_piece!(sys::System, H, dH)
    _callable(H, "H"); _callable(dH, "dH")
    pair = _keep!(sys, (_keep!(sys, H), _keep!(sys, dH)))
    _call(h -> C.lpi_moments_add_product_piece(h, _pair_h_ptr(), _pair_dh_ptr(),
                                               pointer_from_objref(pair)), sys)
end
function _pair_h(u::Cdouble, out::Ptr{Cdouble}, user::Ptr{Cvoid})::Cint
    a, _ = (unsafe_pointer_to_objref(user)::_Callback).f
    _scalar_trampoline(u, out, pointer_from_objref(a))
end
function _pair_dh(u::Cdouble, out::Ptr{Cdouble}, user::Ptr{Cvoid})::Cint
    _, b = (unsafe_pointer_to_objref(user)::_Callback).f
    _scalar_trampoline(u, out, pointer_from_objref(b))
end
_pair_h_ptr() = @cfunction(_pair_h, Cint, (Cdouble, Ptr{Cdouble}, Ptr{Cvoid}))
_pair_dh_ptr() = @cfunction(_pair_dh, Cint, (Cdouble, Ptr{Cdouble}, Ptr{Cvoid}))

# ---- sine-Euler -----------------------------------------------------------------
# Julia is column-major: modes(sys)[a+1, b+1] is mode (a, b); the C layout is
# row-major [a*N + b], so arrays are transposed on the way in and out.

function sine_euler_size(sys::System)
    out = Ref{Int32}(0); _call(h -> C.lpi_sine_euler_size(h, out), sys); Int(out[])
end
function modes(sys::System)
    N = sine_euler_size(sys)
    buf = Matrix{ComplexF64}(undef, N, N)   # interleaved re, im in memory
    GC.@preserve buf _call(h -> C.lpi_sine_euler_get_modes(h, Ptr{Cdouble}(pointer(buf)), 2 * N * N), sys)
    permutedims(buf)
end
# C sees only the element count, which a 49 x 1 array shares with 7 x 7: an
# array of any other shape than N x N is refused here (LPI_ERR_SIZE), before
# the library is called, so nothing changes.
function _require_square(sys::System, w::AbstractMatrix, what::AbstractString)
    N = sine_euler_size(sys)
    size(w) == (N, N) ||
        throw(LiePoissonError(-3, status_name(-3), "$what must be $N x $N, not $(size(w, 1)) x $(size(w, 2))"))
    nothing
end
function set_modes!(sys::System, w::AbstractMatrix{<:Number})
    _require_square(sys, w, "modes")
    buf = Matrix{ComplexF64}(permutedims(w))
    GC.@preserve buf _call(h -> C.lpi_sine_euler_set_modes(h, Ptr{Cdouble}(pointer(buf)), 2 * length(buf)), sys)
end
function grid(sys::System)
    N = sine_euler_size(sys)
    buf = Matrix{Float64}(undef, N, N)
    _call(h -> C.lpi_sine_euler_get_grid(h, buf, N * N), sys)
    permutedims(buf)
end
function set_grid!(sys::System, w::AbstractMatrix{<:Real})
    _require_square(sys, w, "grid")
    buf = Matrix{Float64}(permutedims(w))
    _call(h -> C.lpi_sine_euler_set_grid(h, buf, length(buf)), sys)
end
enstrophy(sys::System) = (out = Ref{Float64}(0.0); _call(h -> C.lpi_sine_euler_enstrophy(h, out), sys); out[])
function casimir_traces(sys::System, kmax::Integer)
    out = Vector{Float64}(undef, max(kmax, 1))
    _call(h -> C.lpi_sine_euler_casimir_traces(h, kmax, out), sys); out[1:kmax]
end
function fft_floor(sys::System, nsteps::Integer)
    s = Ref{Float64}(0.0); t = Ref{Float64}(0.0)
    _call(h -> C.lpi_sine_euler_fft_floor(h, nsteps, s, t), sys)
    (seconds_per_step = s[], transforms_per_step = t[])
end
# FFTW planning rigor: "estimate" (default, deterministic), "measure", "patient".
set_planning!(sys::System, rigor::AbstractString) = _call(h -> C.lpi_sine_euler_set_planning(h, rigor), sys)
function planning(sys::System)
    out = Ref{Cstring}(C_NULL); _call(h -> C.lpi_sine_euler_get_planning(h, out), sys); unsafe_string(out[])
end

# The sine-bracket family: H = 1/2 sum lambda_n |w_n|^2 + sum conj(f_n) w_n
# (lambda[a+1, b+1] and f[a+1, b+1] belong to mode (a, b); f = nothing for 0).
function set_hamiltonian!(sys::System, lambda::AbstractMatrix{<:Real},
                          f::Union{Nothing,AbstractMatrix{<:Number}} = nothing)
    _require_square(sys, lambda, "lambda")
    f === nothing || _require_square(sys, f, "f")
    lam = Matrix{Float64}(permutedims(lambda))
    if f === nothing
        _call(h -> C.lpi_sine_euler_set_hamiltonian(h, lam, length(lam), C_NULL, 0), sys)
    else
        fbuf = Matrix{ComplexF64}(permutedims(f))
        GC.@preserve fbuf _call(h -> C.lpi_sine_euler_set_hamiltonian(h, lam, length(lam),
                                                                  Ptr{Cdouble}(pointer(fbuf)), 2 * length(fbuf)), sys)
    end
end
"""stream_function(sys): psi = sum (lambda_n w_n + f_n) exp(i n.x) on the grid."""
function stream_function(sys::System)
    N = sine_euler_size(sys)
    buf = Matrix{Float64}(undef, N, N)
    _call(h -> C.lpi_sine_euler_get_stream(h, buf, N * N), sys)
    permutedims(buf)
end
"""spectrum(sys): (energy, enstrophy) shell sums, entry k for k - 1/2 <= |n| < k + 1/2."""
function spectrum(sys::System)
    shells = Ref{Csize_t}(0)
    _call(h -> C.lpi_sine_euler_spectrum(h, C_NULL, C_NULL, 0, shells), sys)  # a query of K
    e = Vector{Float64}(undef, shells[]); z = Vector{Float64}(undef, shells[])
    _call(h -> C.lpi_sine_euler_spectrum(h, e, z, length(e), shells), sys)
    (energy = e, enstrophy = z)
end

# ---- FFTW wisdom (process-wide) ------------------------------------------------------
fftw_wisdom_import_file(path::AbstractString) = _check(C.lpi_fftw_wisdom_import_file(path))
fftw_wisdom_export_file(path::AbstractString) = _check(C.lpi_fftw_wisdom_export_file(path))
fftw_wisdom_import_string(w::AbstractString) = _check(C.lpi_fftw_wisdom_import_string(w))
function fftw_wisdom_export_string()
    len = Ref{Csize_t}(0)
    _check(C.lpi_fftw_wisdom_export_string(C_NULL, 0, len))  # a query of the length
    # The wisdom is the process's: another thread planning between the query
    # and the copy adds to it, and the buffer is then made again at the new
    # length (given with LPI_ERR_SIZE).
    buf, status = UInt8[], -3  # LPI_ERR_SIZE
    for _ in 1:100
        buf = Vector{UInt8}(undef, len[] + 1)
        status = C.lpi_fftw_wisdom_export_string(buf, length(buf), len)
        status == -3 || break
    end
    _check(status)
    String(buf[1:len[]])
end

export LiePoissonError, RigidBody, Pendulum, Generic, Moments, SineEuler, System, save, load,
    save_bytes, load_bytes,
    kind, method_name, split_name, version_number,
    set_method!, set_split!, set_composition!, flows_per_step, set_implicit_options!,
    set_threads!, dim, state, set_state!, step!, energy, casimir_count, casimirs, last_error,
    exact, poisson_rank, add_piece!, add_casimir!, add_product_piece!, sine_euler_size, modes,
    set_modes!, grid, set_grid!, enstrophy, casimir_traces, fft_floor, set_planning!, planning,
    set_hamiltonian!, stream_function, spectrum

end # module
