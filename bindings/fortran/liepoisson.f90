! liepoisson for Fortran 2018 (error stop with a message made at run time;
! gfortran builds it by default): the module liepoisson.
!
! Two layers over the C library (include/liepoisson.h):
!   c_lpi_<name>  bind(C) interfaces of every public function, exactly as in C;
!   lpi_<name>    Fortran-friendly wrappers: character strings in and out
!                 (trailing blanks dropped), assumed-shape arrays (their size
!                 is passed as the length), and an optional integer status
!                 argument. When status is absent, a failure stops the program
!                 with the library's message (as Fortran I/O does without
!                 iostat=); when present, it receives LPI_OK, the negative
!                 LPI_ERR_* code (then lpi_last_error(sys) gives the message;
!                 for LPI_ERR_BUSY because another thread is inside a call on
!                 the handle, lpi_last_error(c_null_ptr), as in C: the
!                 handle's own is that thread's to write) or, from lpi_step,
!                 the positive LPI_STOPPED (not a failure: never stops).
! An empty array is passed as a length of 0 whatever made it (gfortran
! passes an empty array constructor as a NULL address, which C would refuse
! as a NULL pointer).
! What C cannot see is refused here, before any C call and changing nothing:
! a string holding a NUL (LPI_ERR_INVALID: C would stop reading there), a
! negative dim (LPI_ERR_INVALID), sine-Euler arrays not N x N and the four
! bracket arrays of lpi_generic_create differing in length, and an array for
! lpi_rigid_body_exact of other than 3 values (LPI_ERR_SIZE), and an integer
! outside the C parameter's 32 bits (LPI_ERR_INVALID: see below).
! lpi_last_error does not describe these (it keeps the message of the
! library's last failure on the handle, which may be an older call's): the
! stop message does, and with status present the code alone tells them.
! Every wrapper is recursive: a callback may call the library again (on
! another handle, or read its own from an observer), which a procedure not
! declared so may not be (gfortran -fcheck=recursion stopped such a call).
! Integer kinds: build the module with the program's own default integer
! kind, 4 or 8 (-fdefault-integer-8 programs: cmake
! -DCMAKE_Fortran_FLAGS=-fdefault-integer-8; against a module of the other
! kind the compiler refuses their status arguments). Status arguments, the LPI_* constants and the
! counts and indices of the wrappers are then of that kind. Where C takes a
! 32-bit int (N, thread count, max_iterations, size(traces), bracket and
! piece indices), a value outside it is refused (LPI_ERR_INVALID, naming the
! argument) instead of being narrowed to another number (2**32 + 3 to 3);
! lpi_method_* give ""/-1 and lpi_status_* the unknown status's answer for
! an index outside it. A size from C that does not fit a default integer
! (lpi_dim, ranks, counts) is LPI_ERR_OVERFLOW. Index arrays may be 32- or
! 64-bit integers (lpi_generic_create, lpi_add_piece), counts of lpi_step
! default or 64-bit.
! Handles are type(c_ptr). Index sets and bracket indices are 0-based, as in C.
! Sine-Euler modes and grids are arrays w(0:N-1, 0:N-1) with w(a, b) = mode
! (a, b) (resp. the vorticity at (2 pi a/N, 2 pi b/N)), of exactly that shape;
! the wrappers transpose to and from the C row-major layout.
! Callbacks are bind(C) functions matching the abstract interfaces
! lpi_gradient_fn, lpi_energy_fn, lpi_casimir_fn, lpi_scalar_fn and
! lpi_observer_fn.
module liepoisson
    use, intrinsic :: iso_c_binding
    implicit none
    private

    ! Status codes: the values are part of the C ABI (append-only). Of
    ! default kind, as the status arguments are (-fdefault-integer-8 too).
    integer, parameter, public :: LPI_OK = 0, LPI_ERR_NULL = -1, LPI_ERR_INVALID = -2, &
        LPI_ERR_SIZE = -3, LPI_ERR_NONFINITE = -4, LPI_ERR_NOT_ABELIAN = -5, &
        LPI_ERR_UNSUPPORTED = -6, LPI_ERR_NO_MEMORY = -7, LPI_ERR_INTERNAL = -8, &
        LPI_ERR_CALLBACK = -9, LPI_ERR_NO_CONVERGENCE = -10, LPI_ERR_IO = -11, LPI_ERR_FORMAT = -12, &
        LPI_ERR_BUSY = -13, LPI_ERR_OVERFLOW = -14, LPI_STOPPED = 1

    ! ---- callback types ------------------------------------------------------
    abstract interface
        integer(c_int) function lpi_gradient_fn(n, x_sigma, grad, user) bind(C)
            import :: c_int, c_size_t, c_double, c_ptr
            integer(c_size_t), value :: n
            real(c_double), intent(in) :: x_sigma(n)
            real(c_double), intent(out) :: grad(n)
            type(c_ptr), value :: user
        end function
        integer(c_int) function lpi_energy_fn(n, x_sigma, h, user) bind(C)
            import :: c_int, c_size_t, c_double, c_ptr
            integer(c_size_t), value :: n
            real(c_double), intent(in) :: x_sigma(n)
            real(c_double), intent(out) :: h
            type(c_ptr), value :: user
        end function
        integer(c_int) function lpi_casimir_fn(dim, x, out, user) bind(C)
            import :: c_int, c_size_t, c_double, c_ptr
            integer(c_size_t), value :: dim
            real(c_double), intent(in) :: x(dim)
            real(c_double), intent(out) :: out
            type(c_ptr), value :: user
        end function
        integer(c_int) function lpi_scalar_fn(u, out, user) bind(C)
            import :: c_int, c_double, c_ptr
            real(c_double), value :: u
            real(c_double), intent(out) :: out
            type(c_ptr), value :: user
        end function
        ! Called by lpi_step after every every-th step; non-zero stops it.
        integer(c_int) function lpi_observer_fn(sys, step, t, user) bind(C)
            import :: c_int, c_int64_t, c_double, c_ptr
            type(c_ptr), value :: sys
            integer(c_int64_t), value :: step
            real(c_double), value :: t
            type(c_ptr), value :: user
        end function
    end interface
    public :: lpi_gradient_fn, lpi_energy_fn, lpi_casimir_fn, lpi_scalar_fn, lpi_observer_fn

    ! ---- the C functions, one interface each ----------------------------------
    interface
        ! version, status codes, methods
        type(c_ptr) function c_lpi_version_string() bind(C, name="lpi_version_string")
            import :: c_ptr
        end function
        integer(c_int) function c_lpi_version_number() bind(C, name="lpi_version_number")
            import :: c_int
        end function
        type(c_ptr) function c_lpi_status_name(status) bind(C, name="lpi_status_name")
            import :: c_ptr, c_int
            integer(c_int), value :: status
        end function
        type(c_ptr) function c_lpi_status_message(status) bind(C, name="lpi_status_message")
            import :: c_ptr, c_int
            integer(c_int), value :: status
        end function
        integer(c_int) function c_lpi_method_count() bind(C, name="lpi_method_count")
            import :: c_int
        end function
        type(c_ptr) function c_lpi_method_name(i) bind(C, name="lpi_method_name")
            import :: c_ptr, c_int
            integer(c_int), value :: i
        end function
        integer(c_int) function c_lpi_method_order(i) bind(C, name="lpi_method_order")
            import :: c_int
            integer(c_int), value :: i
        end function
        integer(c_int) function c_lpi_method_is_poisson(i) bind(C, name="lpi_method_is_poisson")
            import :: c_int
            integer(c_int), value :: i
        end function
        integer(c_int) function c_lpi_method_stages(i) bind(C, name="lpi_method_stages")
            import :: c_int
            integer(c_int), value :: i
        end function
        type(c_ptr) function c_lpi_method_reference(i) bind(C, name="lpi_method_reference")
            import :: c_ptr, c_int
            integer(c_int), value :: i
        end function
        ! systems
        integer(c_int) function c_lpi_rigid_body_create(out, i1, i2, i3) &
                bind(C, name="lpi_rigid_body_create")
            import :: c_int, c_ptr, c_double
            type(c_ptr), intent(out) :: out
            real(c_double), value :: i1, i2, i3
        end function
        integer(c_int) function c_lpi_rigid_body_exact(sys, t, out) bind(C, name="lpi_rigid_body_exact")
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sys
            real(c_double), value :: t
            real(c_double), intent(out) :: out(3)
        end function
        integer(c_int) function c_lpi_pendulum_create(out) bind(C, name="lpi_pendulum_create")
            import :: c_int, c_ptr
            type(c_ptr), intent(out) :: out
        end function
        integer(c_int) function c_lpi_destroy(sys) bind(C, name="lpi_destroy")
            import :: c_int, c_ptr
            type(c_ptr), value :: sys
        end function
        integer(c_int) function c_lpi_set_method(sys, name) bind(C, name="lpi_set_method")
            import :: c_int, c_ptr, c_char
            type(c_ptr), value :: sys
            character(kind=c_char), intent(in) :: name(*)
        end function
        integer(c_int) function c_lpi_set_split(sys, name) bind(C, name="lpi_set_split")
            import :: c_int, c_ptr, c_char
            type(c_ptr), value :: sys
            character(kind=c_char), intent(in) :: name(*)
        end function
        type(c_ptr) function c_lpi_kind(sys) bind(C, name="lpi_kind")
            import :: c_ptr
            type(c_ptr), value :: sys
        end function
        type(c_ptr) function c_lpi_get_method(sys) bind(C, name="lpi_get_method")
            import :: c_ptr
            type(c_ptr), value :: sys
        end function
        type(c_ptr) function c_lpi_get_split(sys) bind(C, name="lpi_get_split")
            import :: c_ptr
            type(c_ptr), value :: sys
        end function
        integer(c_size_t) function c_lpi_dim(sys) bind(C, name="lpi_dim")
            import :: c_size_t, c_ptr
            type(c_ptr), value :: sys
        end function
        integer(c_int) function c_lpi_set_state(sys, x, n) bind(C, name="lpi_set_state")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            real(c_double), intent(in) :: x(*)
            integer(c_size_t), value :: n
        end function
        integer(c_int) function c_lpi_get_state(sys, x, n) bind(C, name="lpi_get_state")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            real(c_double), intent(inout) :: x(*)
            integer(c_size_t), value :: n
        end function
        integer(c_int) function c_lpi_step(sys, dt, nsteps) bind(C, name="lpi_step")
            import :: c_int, c_ptr, c_double, c_int64_t
            type(c_ptr), value :: sys
            real(c_double), value :: dt
            integer(c_int64_t), value :: nsteps
        end function
        integer(c_int) function c_lpi_set_observer(sys, every, fn, user) bind(C, name="lpi_set_observer")
            import :: c_int, c_ptr, c_int64_t, c_funptr
            type(c_ptr), value :: sys
            integer(c_int64_t), value :: every
            type(c_funptr), value :: fn
            type(c_ptr), value :: user
        end function
        real(c_double) function c_lpi_time(sys) bind(C, name="lpi_time")
            import :: c_double, c_ptr
            type(c_ptr), value :: sys
        end function
        integer(c_int) function c_lpi_energy(sys, out) bind(C, name="lpi_energy")
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sys
            real(c_double), intent(out) :: out
        end function
        integer(c_size_t) function c_lpi_casimir_count(sys) bind(C, name="lpi_casimir_count")
            import :: c_size_t, c_ptr
            type(c_ptr), value :: sys
        end function
        integer(c_int) function c_lpi_casimirs(sys, out, n) bind(C, name="lpi_casimirs")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            real(c_double), intent(inout) :: out(*)
            integer(c_size_t), value :: n
        end function
        type(c_ptr) function c_lpi_last_error(sys) bind(C, name="lpi_last_error")
            import :: c_ptr
            type(c_ptr), value :: sys
        end function
        ! composition methods, implicit baselines
        integer(c_int) function c_lpi_set_composition(sys, n, gammas) bind(C, name="lpi_set_composition")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            integer(c_size_t), value :: n
            real(c_double), intent(in) :: gammas(*)
        end function
        integer(c_int) function c_lpi_flows_per_step(sys, out) bind(C, name="lpi_flows_per_step")
            import :: c_int, c_ptr, c_size_t
            type(c_ptr), value :: sys
            integer(c_size_t), intent(out) :: out
        end function
        integer(c_int) function c_lpi_set_implicit_options(sys, tolerance, max_iterations) &
                bind(C, name="lpi_set_implicit_options")
            import :: c_int, c_ptr, c_double, c_int32_t
            type(c_ptr), value :: sys
            real(c_double), value :: tolerance
            integer(c_int32_t), value :: max_iterations
        end function
        ! generic systems and the moment algebra
        integer(c_int) function c_lpi_generic_create(out, dim, nnz, i, j, k, c) &
                bind(C, name="lpi_generic_create")
            import :: c_int, c_ptr, c_size_t, c_int32_t, c_double
            type(c_ptr), intent(out) :: out
            integer(c_size_t), value :: dim, nnz
            integer(c_int32_t), intent(in) :: i(*), j(*), k(*)
            real(c_double), intent(in) :: c(*)
        end function
        integer(c_int) function c_lpi_add_piece(sys, n, indices, grad, energy, user) &
                bind(C, name="lpi_add_piece")
            import :: c_int, c_ptr, c_size_t, c_int32_t, c_funptr
            type(c_ptr), value :: sys
            integer(c_size_t), value :: n
            integer(c_int32_t), intent(in) :: indices(*)
            type(c_funptr), value :: grad, energy
            type(c_ptr), value :: user
        end function
        integer(c_int) function c_lpi_add_casimir(sys, fn, user) bind(C, name="lpi_add_casimir")
            import :: c_int, c_ptr, c_funptr
            type(c_ptr), value :: sys
            type(c_funptr), value :: fn
            type(c_ptr), value :: user
        end function
        integer(c_int) function c_lpi_poisson_rank(sys, x, n, rank) bind(C, name="lpi_poisson_rank")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            real(c_double), intent(in) :: x(*)
            integer(c_size_t), value :: n
            integer(c_size_t), intent(out) :: rank
        end function
        integer(c_int) function c_lpi_moments_create(out) bind(C, name="lpi_moments_create")
            import :: c_int, c_ptr
            type(c_ptr), intent(out) :: out
        end function
        integer(c_int) function c_lpi_moments_add_product_piece(sys, h, dh, user) &
                bind(C, name="lpi_moments_add_product_piece")
            import :: c_int, c_ptr, c_funptr
            type(c_ptr), value :: sys
            type(c_funptr), value :: h, dh
            type(c_ptr), value :: user
        end function
        ! sine-Euler, threads, FFTW wisdom
        integer(c_int) function c_lpi_sine_euler_create(out, n) bind(C, name="lpi_sine_euler_create")
            import :: c_int, c_ptr, c_int32_t
            type(c_ptr), intent(out) :: out
            integer(c_int32_t), value :: n
        end function
        integer(c_int) function c_lpi_sine_euler_size(sys, n) bind(C, name="lpi_sine_euler_size")
            import :: c_int, c_ptr, c_int32_t
            type(c_ptr), value :: sys
            integer(c_int32_t), intent(out) :: n
        end function
        integer(c_int) function c_lpi_sine_euler_set_modes(sys, re_im, n) &
                bind(C, name="lpi_sine_euler_set_modes")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            real(c_double), intent(in) :: re_im(*)
            integer(c_size_t), value :: n
        end function
        integer(c_int) function c_lpi_sine_euler_get_modes(sys, re_im, n) &
                bind(C, name="lpi_sine_euler_get_modes")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            real(c_double), intent(inout) :: re_im(*)
            integer(c_size_t), value :: n
        end function
        integer(c_int) function c_lpi_sine_euler_set_grid(sys, w, n) bind(C, name="lpi_sine_euler_set_grid")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            real(c_double), intent(in) :: w(*)
            integer(c_size_t), value :: n
        end function
        integer(c_int) function c_lpi_sine_euler_get_grid(sys, w, n) bind(C, name="lpi_sine_euler_get_grid")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            real(c_double), intent(inout) :: w(*)
            integer(c_size_t), value :: n
        end function
        integer(c_int) function c_lpi_sine_euler_enstrophy(sys, out) bind(C, name="lpi_sine_euler_enstrophy")
            import :: c_int, c_ptr, c_double
            type(c_ptr), value :: sys
            real(c_double), intent(out) :: out
        end function
        integer(c_int) function c_lpi_sine_euler_casimir_traces(sys, kmax, out) &
                bind(C, name="lpi_sine_euler_casimir_traces")
            import :: c_int, c_ptr, c_int32_t, c_double
            type(c_ptr), value :: sys
            integer(c_int32_t), value :: kmax
            real(c_double), intent(inout) :: out(*)
        end function
        integer(c_int) function c_lpi_sine_euler_fft_floor(sys, nsteps, seconds_per_step, &
                transforms_per_step) bind(C, name="lpi_sine_euler_fft_floor")
            import :: c_int, c_ptr, c_int64_t, c_double
            type(c_ptr), value :: sys
            integer(c_int64_t), value :: nsteps
            real(c_double), intent(out) :: seconds_per_step, transforms_per_step
        end function
        integer(c_int) function c_lpi_sine_euler_set_planning(sys, rigor) &
                bind(C, name="lpi_sine_euler_set_planning")
            import :: c_int, c_ptr, c_char
            type(c_ptr), value :: sys
            character(kind=c_char), intent(in) :: rigor(*)
        end function
        integer(c_int) function c_lpi_sine_euler_get_planning(sys, rigor) &
                bind(C, name="lpi_sine_euler_get_planning")
            import :: c_int, c_ptr
            type(c_ptr), value :: sys
            type(c_ptr), intent(out) :: rigor
        end function
        integer(c_int) function c_lpi_sine_euler_set_hamiltonian(sys, lambda, n_lambda, f, n_f) &
                bind(C, name="lpi_sine_euler_set_hamiltonian")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            real(c_double), intent(in) :: lambda(*)
            integer(c_size_t), value :: n_lambda
            type(c_ptr), value :: f
            integer(c_size_t), value :: n_f
        end function
        integer(c_int) function c_lpi_sine_euler_get_stream(sys, psi, n) bind(C, name="lpi_sine_euler_get_stream")
            import :: c_int, c_ptr, c_double, c_size_t
            type(c_ptr), value :: sys
            real(c_double), intent(inout) :: psi(*)
            integer(c_size_t), value :: n
        end function
        ! The buffers as addresses: both NULL (c_null_ptr) with n = 0 asks for
        ! the shell count, which an array argument could not pass.
        integer(c_int) function c_lpi_sine_euler_spectrum(sys, energy, enstrophy, n, shells) &
                bind(C, name="lpi_sine_euler_spectrum")
            import :: c_int, c_ptr, c_size_t
            type(c_ptr), value :: sys, energy, enstrophy
            integer(c_size_t), value :: n
            integer(c_size_t), intent(out) :: shells
        end function
        integer(c_int) function c_lpi_set_threads(sys, n) bind(C, name="lpi_set_threads")
            import :: c_int, c_ptr, c_int32_t
            type(c_ptr), value :: sys
            integer(c_int32_t), value :: n
        end function
        integer(c_int) function c_lpi_fftw_wisdom_import_file(path) bind(C, name="lpi_fftw_wisdom_import_file")
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: path(*)
        end function
        integer(c_int) function c_lpi_fftw_wisdom_export_file(path) bind(C, name="lpi_fftw_wisdom_export_file")
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: path(*)
        end function
        integer(c_int) function c_lpi_fftw_wisdom_import_string(wisdom) &
                bind(C, name="lpi_fftw_wisdom_import_string")
            import :: c_int, c_char
            character(kind=c_char), intent(in) :: wisdom(*)
        end function
        integer(c_int) function c_lpi_fftw_wisdom_export_string(buf, size, length) &
                bind(C, name="lpi_fftw_wisdom_export_string")
            import :: c_int, c_ptr, c_size_t
            type(c_ptr), value :: buf
            integer(c_size_t), value :: size
            integer(c_size_t), intent(out) :: length
        end function
        ! checkpoints
        integer(c_int) function c_lpi_save(sys, path) bind(C, name="lpi_save")
            import :: c_int, c_ptr, c_char
            type(c_ptr), value :: sys
            character(kind=c_char), intent(in) :: path(*)
        end function
        integer(c_int) function c_lpi_load(out, path) bind(C, name="lpi_load")
            import :: c_int, c_ptr, c_char
            type(c_ptr), intent(out) :: out
            character(kind=c_char), intent(in) :: path(*)
        end function
        integer(c_int) function c_lpi_save_buffer(sys, buf, capacity, size) bind(C, name="lpi_save_buffer")
            import :: c_int, c_ptr, c_size_t
            type(c_ptr), value :: sys, buf
            integer(c_size_t), value :: capacity
            integer(c_size_t), intent(out) :: size
        end function
        integer(c_int) function c_lpi_load_buffer(out, buf, size) bind(C, name="lpi_load_buffer")
            import :: c_int, c_ptr, c_size_t
            type(c_ptr), intent(out) :: out
            type(c_ptr), value :: buf
            integer(c_size_t), value :: size
        end function
        ! from the C library, to read C strings
        integer(c_size_t) function c_strlen(s) bind(C, name="strlen")
            import :: c_size_t, c_ptr
            type(c_ptr), value :: s
        end function
    end interface

    public :: c_lpi_version_string, c_lpi_version_number, c_lpi_kind, c_lpi_get_method, &
        c_lpi_get_split, c_lpi_status_name, c_lpi_status_message, c_lpi_method_count, &
        c_lpi_method_name, c_lpi_method_order, c_lpi_method_is_poisson, c_lpi_method_stages, &
        c_lpi_method_reference, c_lpi_rigid_body_create, c_lpi_rigid_body_exact, &
        c_lpi_pendulum_create, c_lpi_destroy, c_lpi_set_method, c_lpi_set_split, c_lpi_dim, &
        c_lpi_set_state, c_lpi_get_state, c_lpi_step, c_lpi_set_observer, c_lpi_time, c_lpi_energy, &
        c_lpi_casimir_count, c_lpi_casimirs, c_lpi_last_error, c_lpi_set_composition, &
        c_lpi_flows_per_step, c_lpi_set_implicit_options, c_lpi_generic_create, c_lpi_add_piece, &
        c_lpi_add_casimir, c_lpi_poisson_rank, c_lpi_moments_create, &
        c_lpi_moments_add_product_piece, c_lpi_sine_euler_create, c_lpi_sine_euler_size, &
        c_lpi_sine_euler_set_modes, c_lpi_sine_euler_get_modes, c_lpi_sine_euler_set_grid, &
        c_lpi_sine_euler_get_grid, c_lpi_sine_euler_enstrophy, c_lpi_sine_euler_casimir_traces, &
        c_lpi_sine_euler_fft_floor, c_lpi_sine_euler_set_planning, c_lpi_sine_euler_get_planning, &
        c_lpi_set_threads, c_lpi_fftw_wisdom_import_file, &
        c_lpi_sine_euler_set_hamiltonian, c_lpi_sine_euler_get_stream, c_lpi_sine_euler_spectrum, &
        c_lpi_fftw_wisdom_export_file, c_lpi_fftw_wisdom_import_string, &
        c_lpi_fftw_wisdom_export_string, c_lpi_save, c_lpi_load, c_lpi_save_buffer, c_lpi_load_buffer

    ! lpi_step, lpi_set_observer and lpi_sine_euler_fft_floor take a default
    ! or 64-bit count, as C's int64_t; lpi_generic_create and lpi_add_piece
    ! 32- or 64-bit index arrays (a literal [0, 1, 2] is either, with the
    ! default kind), the 64-bit ones checked against C's int32_t.
    interface lpi_step
        module procedure lpi_step_i4, lpi_step_i8
    end interface
    interface lpi_set_observer
        module procedure lpi_set_observer_i4, lpi_set_observer_i8
    end interface
    interface lpi_sine_euler_fft_floor
        module procedure lpi_sine_euler_fft_floor_i4, lpi_sine_euler_fft_floor_i8
    end interface
    interface lpi_generic_create
        module procedure lpi_generic_create_i4, lpi_generic_create_i8
    end interface
    interface lpi_add_piece
        module procedure lpi_add_piece_i4, lpi_add_piece_i8
    end interface

    public :: lpi_version_string, lpi_version_number, lpi_kind, lpi_get_method, lpi_get_split, &
        lpi_status_name, lpi_status_message, lpi_method_count, &
        lpi_method_name, lpi_method_order, lpi_method_is_poisson, lpi_method_stages, &
        lpi_method_reference, lpi_rigid_body_create, lpi_rigid_body_exact, lpi_pendulum_create, &
        lpi_destroy, lpi_set_method, lpi_set_split, lpi_dim, lpi_set_state, lpi_get_state, &
        lpi_step, lpi_set_observer, lpi_time, lpi_energy, lpi_casimir_count, lpi_casimirs, &
        lpi_last_error, &
        lpi_set_composition, lpi_flows_per_step, lpi_set_implicit_options, lpi_generic_create, &
        lpi_add_piece, lpi_add_casimir, lpi_poisson_rank, lpi_moments_create, &
        lpi_moments_add_product_piece, lpi_sine_euler_create, lpi_sine_euler_size, &
        lpi_sine_euler_set_modes, lpi_sine_euler_get_modes, lpi_sine_euler_set_grid, &
        lpi_sine_euler_get_grid, lpi_sine_euler_enstrophy, lpi_sine_euler_casimir_traces, &
        lpi_sine_euler_fft_floor, lpi_sine_euler_set_planning, lpi_sine_euler_get_planning, &
        lpi_set_threads, lpi_fftw_wisdom_import_file, &
        lpi_sine_euler_set_hamiltonian, lpi_sine_euler_get_stream, lpi_sine_euler_spectrum, &
        lpi_fftw_wisdom_export_file, lpi_fftw_wisdom_import_string, lpi_fftw_wisdom_export_string, &
        lpi_save, lpi_load, lpi_save_buffer, lpi_load_buffer

contains

    ! ---- helpers ----------------------------------------------------------------

    ! A NUL-terminated C string as a Fortran string ("" for NULL).
    recursive function f_string(p) result(s)
        type(c_ptr), intent(in) :: p
        character(len=:), allocatable :: s
        character(kind=c_char), pointer :: chars(:)
        integer(c_size_t) :: n, q  ! not narrowed to a default integer
        if (.not. c_associated(p)) then
            s = ""
            return
        end if
        n = c_strlen(p)
        call c_f_pointer(p, chars, [n])
        allocate (character(len=n) :: s)
        do q = 1, n
            s(q:q) = chars(q)
        end do
    end function

    ! s less trailing blanks, NUL-terminated for C. Callers refuse a NUL
    ! inside s first (nul_refused): C would end the string there.
    recursive function c_string(s) result(c)
        character(len=*), intent(in) :: s
        character(kind=c_char, len=len_trim(s) + 1) :: c
        c = trim(s)//c_null_char
    end function

    ! A refusal made here, before any C call, of what the C function cannot
    ! see: status receives code, or the program stops with message (C has no
    ! way to take it, so lpi_last_error keeps what it had).
    recursive subroutine refuse(code, message, status)
        integer, intent(in) :: code
        character(len=*), intent(in) :: message
        integer, intent(out), optional :: status
        if (.not. present(status)) &
            error stop "liepoisson: "//f_string(c_lpi_status_name(int(code, c_int)))//": "//message
        status = code
    end subroutine

    ! .true. after refusing s (LPI_ERR_INVALID) when it holds a NUL: C would
    ! take the string before it ("leapfrog"//c_null_char//"x" as "leapfrog").
    recursive logical function nul_refused(s, what, status)
        character(len=*), intent(in) :: s, what
        integer, intent(out), optional :: status
        nul_refused = index(s, c_null_char) > 0
        if (nul_refused) call refuse(LPI_ERR_INVALID, what//" contains a NUL character", status)
    end function

    ! .true. after refusing n < 0 (LPI_ERR_INVALID): int(n, c_size_t) would
    ! wrap it to nearly 2^64, and C would report that number.
    recursive logical function negative_refused(n, what, status)
        integer, intent(in) :: n
        character(len=*), intent(in) :: what
        integer, intent(out), optional :: status
        character(len=24) :: text
        negative_refused = n < 0
        if (negative_refused) then
            write (text, '(i0)') n
            call refuse(LPI_ERR_INVALID, what//" = "//trim(text)//" is negative", status)
        end if
    end function

    ! .true. when n fits C's int32_t (and int: 32 bits wherever gfortran
    ! runs). A default integer of 8 bytes (-fdefault-integer-8) may not:
    ! int(n, c_int32_t) would then give another number (2**32 + 3 as 3).
    recursive logical function fits_int32(n)
        integer(c_int64_t), intent(in) :: n
        fits_int32 = n >= -int(huge(0_c_int32_t), c_int64_t) - 1 .and. n <= huge(0_c_int32_t)
    end function

    ! .true. after refusing n outside C's int32_t (LPI_ERR_INVALID), before
    ! it is narrowed to another number.
    recursive logical function int32_refused(n, what, status)
        integer(c_int64_t), intent(in) :: n
        character(len=*), intent(in) :: what
        integer, intent(out), optional :: status
        character(len=24) :: text
        int32_refused = .not. fits_int32(n)
        if (int32_refused) then
            write (text, '(i0)') n
            call refuse(LPI_ERR_INVALID, what//" = "//trim(text)//" is outside C's 32-bit int", status)
        end if
    end function

    ! .true. after refusing the first element of v outside C's int32_t, as
    ! int32_refused, named what(position).
    recursive logical function indices_refused(v, what, status)
        integer(c_int64_t), intent(in) :: v(:)
        character(len=*), intent(in) :: what
        integer, intent(out), optional :: status
        character(len=24) :: text
        integer(c_int64_t) :: q
        indices_refused = .false.
        do q = 1, size(v, kind=c_int64_t)
            if (.not. fits_int32(v(q))) then
                write (text, '(i0)') q
                indices_refused = int32_refused(v(q), what//"("//trim(text)//")", status)
                return
            end if
        end do
    end function

    ! out = n when the size C gave fits a default integer; otherwise .false.
    ! after refusing it (LPI_ERR_OVERFLOW), out = -1: int(n) would give
    ! another number (beyond 2**31 - 1 without -fdefault-integer-8).
    recursive logical function size_fits(n, out, what, status)
        integer(c_size_t), intent(in) :: n
        integer, intent(out) :: out
        character(len=*), intent(in) :: what
        integer, intent(out), optional :: status
        character(len=24) :: text
        ! A size_t above 2**63 - 1 reads as negative here.
        size_fits = n >= 0 .and. n <= huge(out)
        out = -1
        if (size_fits) then
            out = int(n)
        else
            text = "above 2**63 - 1"
            if (n >= 0) write (text, '(i0)') n
            call refuse(LPI_ERR_OVERFLOW, what//" = "//trim(text)//" does not fit a default integer "// &
                        "(build the module with -fdefault-integer-8)", status)
        end if
    end function

    ! .true. after refusing an array of shape dims (LPI_ERR_SIZE) that is not
    ! N x N on a sine-Euler system: C sees only the element count, which a
    ! 49 x 1 array shares with 7 x 7. Any other handle is left to C to report.
    recursive logical function shape_refused(sys, dims, what, status)
        type(c_ptr), intent(in) :: sys
        integer, intent(in) :: dims(2)
        character(len=*), intent(in) :: what
        integer, intent(out), optional :: status
        integer(c_int32_t) :: n
        character(len=64) :: text
        shape_refused = .false.
        if (c_lpi_sine_euler_size(sys, n) /= LPI_OK) return
        shape_refused = any(dims /= n)
        if (shape_refused) then
            write (text, '(i0, " x ", i0, ", not N x N = ", i0, " x ", i0)') dims, n, n
            call refuse(LPI_ERR_SIZE, what//" is "//trim(text), status)
        end if
    end function

    ! Hands st to status when present; otherwise a failure stops the program.
    recursive subroutine finish(st, sys, status)
        integer(c_int), intent(in) :: st
        type(c_ptr), intent(in) :: sys
        integer, intent(out), optional :: status
        character(len=:), allocatable :: message
        if (present(status)) then
            status = st
        else if (st < 0) then
            ! Refused because another thread is inside a call on the handle:
            ! the message is this thread's, and the handle's is the other
            ! thread's to write (reading it would race with that thread).
            message = ""
            if (st == LPI_ERR_BUSY) message = f_string(c_lpi_last_error(c_null_ptr))
            if (index(message, "another thread is inside a call on this handle") == 0) &
                message = f_string(c_lpi_last_error(sys))
            error stop "liepoisson: "//f_string(c_lpi_status_name(st))//": "//message
        end if
    end subroutine

    ! ---- version, status codes, methods ----------------------------------------

    recursive function lpi_version_string() result(s)
        character(len=:), allocatable :: s
        s = f_string(c_lpi_version_string())
    end function

    ! MAJOR * 10000 + MINOR * 100 + PATCH of the library that runs.
    recursive integer function lpi_version_number()
        lpi_version_number = c_lpi_version_number()
    end function

    ! A status outside C's int is unknown to C: it is asked about INT_MIN,
    ! no status code, instead of the number int(status, c_int) would make.
    recursive function lpi_status_name(status) result(s)
        integer, intent(in) :: status
        character(len=:), allocatable :: s
        s = f_string(c_lpi_status_name(c_status(status)))
    end function

    recursive function lpi_status_message(status) result(s)
        integer, intent(in) :: status
        character(len=:), allocatable :: s
        s = f_string(c_lpi_status_message(c_status(status)))
    end function

    recursive integer(c_int) function c_status(status)
        integer, intent(in) :: status
        c_status = -huge(0_c_int) - 1_c_int
        if (fits_int32(int(status, c_int64_t))) c_status = int(status, c_int)
    end function

    recursive integer function lpi_method_count()
        lpi_method_count = c_lpi_method_count()
    end function

    ! Methods are numbered 0 .. lpi_method_count() - 1, as in C; "" (-1) out
    ! of range, also outside C's int (not asked: int(i, c_int) could make it
    ! a valid index).
    recursive function lpi_method_name(i) result(s)
        integer, intent(in) :: i
        character(len=:), allocatable :: s
        s = ""
        if (fits_int32(int(i, c_int64_t))) s = f_string(c_lpi_method_name(int(i, c_int)))
    end function

    recursive integer function lpi_method_order(i)
        integer, intent(in) :: i
        lpi_method_order = -1
        if (fits_int32(int(i, c_int64_t))) lpi_method_order = c_lpi_method_order(int(i, c_int))
    end function

    recursive integer function lpi_method_is_poisson(i)
        integer, intent(in) :: i
        lpi_method_is_poisson = -1
        if (fits_int32(int(i, c_int64_t))) lpi_method_is_poisson = c_lpi_method_is_poisson(int(i, c_int))
    end function

    recursive integer function lpi_method_stages(i)
        integer, intent(in) :: i
        lpi_method_stages = -1
        if (fits_int32(int(i, c_int64_t))) lpi_method_stages = c_lpi_method_stages(int(i, c_int))
    end function

    recursive function lpi_method_reference(i) result(s)
        integer, intent(in) :: i
        character(len=:), allocatable :: s
        s = ""
        if (fits_int32(int(i, c_int64_t))) s = f_string(c_lpi_method_reference(int(i, c_int)))
    end function

    ! ---- systems ------------------------------------------------------------------

    recursive subroutine lpi_rigid_body_create(sys, i1, i2, i3, status)
        type(c_ptr), intent(out) :: sys
        real(c_double), intent(in) :: i1, i2, i3
        integer, intent(out), optional :: status
        call finish(c_lpi_rigid_body_create(sys, i1, i2, i3), c_null_ptr, status)
    end subroutine

    ! m is left as it was on a failure (also a strided section: C writes a
    ! local copy).
    recursive subroutine lpi_rigid_body_exact(sys, t, m, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(in) :: t
        real(c_double), intent(inout) :: m(:)
        integer, intent(out), optional :: status
        character(len=24) :: text
        real(c_double) :: out(3)
        integer(c_int) :: st
        ! C writes three values and is told no length: any other size is
        ! refused here (a size 2 array was written past its end).
        if (size(m) /= 3) then
            write (text, '(i0)') size(m)
            call refuse(LPI_ERR_SIZE, "m has "//trim(text)//" elements, the exact solution 3", status)
            return
        end if
        st = c_lpi_rigid_body_exact(sys, t, out)
        if (st == LPI_OK) m = out
        call finish(st, sys, status)
    end subroutine

    recursive subroutine lpi_pendulum_create(sys, status)
        type(c_ptr), intent(out) :: sys
        integer, intent(out), optional :: status
        call finish(c_lpi_pendulum_create(sys), c_null_ptr, status)
    end subroutine

    ! Releases the handle and sets sys to c_null_ptr (a null handle is a no-op).
    ! From one of the handle's own callbacks: LPI_ERR_BUSY, nothing released.
    recursive subroutine lpi_destroy(sys, status)
        type(c_ptr), intent(inout) :: sys
        integer, intent(out), optional :: status
        integer(c_int) :: st
        st = c_lpi_destroy(sys)
        if (st == LPI_OK) sys = c_null_ptr
        call finish(st, sys, status)
    end subroutine

    recursive subroutine lpi_set_method(sys, name, status)
        type(c_ptr), intent(in) :: sys
        character(len=*), intent(in) :: name
        integer, intent(out), optional :: status
        if (nul_refused(name, "lpi_set_method: name", status)) return
        call finish(c_lpi_set_method(sys, c_string(name)), sys, status)
    end subroutine

    recursive subroutine lpi_set_split(sys, name, status)
        type(c_ptr), intent(in) :: sys
        character(len=*), intent(in) :: name
        integer, intent(out), optional :: status
        if (nul_refused(name, "lpi_set_split: name", status)) return
        call finish(c_lpi_set_split(sys, c_string(name)), sys, status)
    end subroutine

    ! A dim beyond a default integer stops the program (LPI_ERR_OVERFLOW:
    ! no status to take it, so size_fits returns only when it fits).
    recursive integer function lpi_dim(sys)
        type(c_ptr), intent(in) :: sys
        integer :: n
        if (size_fits(c_lpi_dim(sys), n, "lpi_dim")) continue
        lpi_dim = n
    end function

    ! size(x) must equal lpi_dim(sys).
    recursive subroutine lpi_set_state(sys, x, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(in) :: x(:)
        integer, intent(out), optional :: status
        real(c_double) :: none(1) = 0  ! saved: read by nobody (a length of 0)
        if (size(x) == 0) then
            call finish(c_lpi_set_state(sys, none, 0_c_size_t), sys, status)
        else
            call finish(c_lpi_set_state(sys, x, size(x, kind=c_size_t)), sys, status)
        end if
    end subroutine

    recursive subroutine lpi_get_state(sys, x, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(inout) :: x(:)
        integer, intent(out), optional :: status
        call finish(c_lpi_get_state(sys, x, size(x, kind=c_size_t)), sys, status)
    end subroutine

    recursive subroutine lpi_step_i4(sys, dt, nsteps, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(in) :: dt
        integer(c_int32_t), intent(in) :: nsteps
        integer, intent(out), optional :: status
        call finish(c_lpi_step(sys, dt, int(nsteps, c_int64_t)), sys, status)
    end subroutine

    recursive subroutine lpi_step_i8(sys, dt, nsteps, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(in) :: dt
        integer(c_int64_t), intent(in) :: nsteps
        integer, intent(out), optional :: status
        call finish(c_lpi_step(sys, dt, nsteps), sys, status)
    end subroutine

    ! Sets the observer of lpi_step (every >= 1, a default or 64-bit
    ! integer); without fn, removes it.
    recursive subroutine lpi_set_observer_i4(sys, every, fn, user, status)
        type(c_ptr), intent(in) :: sys
        integer(c_int32_t), intent(in) :: every
        procedure(lpi_observer_fn), optional :: fn
        type(c_ptr), intent(in), optional :: user
        integer, intent(out), optional :: status
        call lpi_set_observer_i8(sys, int(every, c_int64_t), fn, user, status)
    end subroutine

    recursive subroutine lpi_set_observer_i8(sys, every, fn, user, status)
        type(c_ptr), intent(in) :: sys
        integer(c_int64_t), intent(in) :: every
        procedure(lpi_observer_fn), optional :: fn
        type(c_ptr), intent(in), optional :: user
        integer, intent(out), optional :: status
        type(c_ptr) :: u
        type(c_funptr) :: f
        u = c_null_ptr
        if (present(user)) u = user
        f = c_null_funptr
        if (present(fn)) f = c_funloc(fn)
        call finish(c_lpi_set_observer(sys, every, f, u), sys, status)
    end subroutine

    recursive real(c_double) function lpi_time(sys)
        type(c_ptr), intent(in) :: sys
        lpi_time = c_lpi_time(sys)
    end function

    recursive subroutine lpi_energy(sys, h, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(out) :: h
        integer, intent(out), optional :: status
        call finish(c_lpi_energy(sys, h), sys, status)
    end subroutine

    recursive integer function lpi_casimir_count(sys)
        type(c_ptr), intent(in) :: sys
        integer :: n
        if (size_fits(c_lpi_casimir_count(sys), n, "lpi_casimir_count")) continue  ! as lpi_dim
        lpi_casimir_count = n
    end function

    ! size(c) must equal lpi_casimir_count(sys).
    recursive subroutine lpi_casimirs(sys, c, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(inout) :: c(:)
        integer, intent(out), optional :: status
        call finish(c_lpi_casimirs(sys, c, size(c, kind=c_size_t)), sys, status)
    end subroutine

    ! The message of the last failure on sys; c_null_ptr gives the calling
    ! thread's last failure of a call without a handle (a failed create).
    ! The system's kind ("rigid-body", ..., "sine-euler"), method and split
    ! names ("" for a null handle).
    recursive function lpi_kind(sys) result(s)
        type(c_ptr), intent(in) :: sys
        character(len=:), allocatable :: s
        s = f_string(c_lpi_kind(sys))
    end function

    recursive function lpi_get_method(sys) result(s)
        type(c_ptr), intent(in) :: sys
        character(len=:), allocatable :: s
        s = f_string(c_lpi_get_method(sys))
    end function

    recursive function lpi_get_split(sys) result(s)
        type(c_ptr), intent(in) :: sys
        character(len=:), allocatable :: s
        s = f_string(c_lpi_get_split(sys))
    end function

    recursive function lpi_last_error(sys) result(s)
        type(c_ptr), intent(in) :: sys
        character(len=:), allocatable :: s
        s = f_string(c_lpi_last_error(sys))
    end function

    ! ---- composition methods, implicit baselines ---------------------------------

    recursive subroutine lpi_set_composition(sys, gammas, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(in) :: gammas(:)
        integer, intent(out), optional :: status
        real(c_double) :: none(1) = 0  ! saved: read by nobody (a length of 0)
        if (size(gammas) == 0) then
            call finish(c_lpi_set_composition(sys, 0_c_size_t, none), sys, status)
        else
            call finish(c_lpi_set_composition(sys, size(gammas, kind=c_size_t), gammas), sys, status)
        end if
    end subroutine

    recursive subroutine lpi_flows_per_step(sys, flows, status)
        type(c_ptr), intent(in) :: sys
        integer, intent(out) :: flows
        integer, intent(out), optional :: status
        integer(c_size_t) :: n
        integer(c_int) :: st
        n = 0
        st = c_lpi_flows_per_step(sys, n)
        if (size_fits(n, flows, "lpi_flows_per_step: flows", status)) call finish(st, sys, status)
    end subroutine

    recursive subroutine lpi_set_implicit_options(sys, tolerance, max_iterations, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(in) :: tolerance
        integer, intent(in) :: max_iterations
        integer, intent(out), optional :: status
        if (int32_refused(int(max_iterations, c_int64_t), "lpi_set_implicit_options: max_iterations", &
                          status)) return
        call finish(c_lpi_set_implicit_options(sys, tolerance, int(max_iterations, c_int32_t)), &
                    sys, status)
    end subroutine

    ! ---- generic systems and the moment algebra ------------------------------------

    ! {x_i, x_j} = sum c x_k over the entries (i(e), j(e), k(e), c(e)), 0-based.
    recursive subroutine lpi_generic_create_i4(sys, dim, i, j, k, c, status)
        type(c_ptr), intent(out) :: sys
        integer, intent(in) :: dim
        integer(c_int32_t), intent(in) :: i(:), j(:), k(:)
        real(c_double), intent(in) :: c(:)
        integer, intent(out), optional :: status
        sys = c_null_ptr
        if (size(j) /= size(i) .or. size(k) /= size(i) .or. size(c) /= size(i)) then
            ! Checked here: the C function cannot see the four lengths.
            call refuse(LPI_ERR_SIZE, "lpi_generic_create: i, j, k and c differ in length", status)
            return
        end if
        if (negative_refused(dim, "lpi_generic_create: dim", status)) return
        call finish(c_lpi_generic_create(sys, int(dim, c_size_t), size(i, kind=c_size_t), i, j, k, c), &
                    c_null_ptr, status)
    end subroutine

    recursive subroutine lpi_generic_create_i8(sys, dim, i, j, k, c, status)
        type(c_ptr), intent(out) :: sys
        integer, intent(in) :: dim
        integer(c_int64_t), intent(in) :: i(:), j(:), k(:)
        real(c_double), intent(in) :: c(:)
        integer, intent(out), optional :: status
        sys = c_null_ptr
        if (indices_refused(i, "lpi_generic_create: i", status)) return
        if (indices_refused(j, "lpi_generic_create: j", status)) return
        if (indices_refused(k, "lpi_generic_create: k", status)) return
        call lpi_generic_create_i4(sys, dim, int(i, c_int32_t), int(j, c_int32_t), int(k, c_int32_t), c, status)
    end subroutine

    ! Appends the piece on the 0-based abelian index set indices.
    recursive subroutine lpi_add_piece_i4(sys, indices, grad, energy, user, status)
        type(c_ptr), intent(in) :: sys
        integer(c_int32_t), intent(in) :: indices(:)
        procedure(lpi_gradient_fn) :: grad
        procedure(lpi_energy_fn) :: energy
        type(c_ptr), intent(in), optional :: user
        integer, intent(out), optional :: status
        type(c_ptr) :: u
        integer(c_int32_t) :: none(1) = 0  ! saved: read by nobody (a length of 0)
        u = c_null_ptr
        if (present(user)) u = user
        if (size(indices) == 0) then
            call finish(c_lpi_add_piece(sys, 0_c_size_t, none, c_funloc(grad), c_funloc(energy), u), sys, status)
        else
            call finish(c_lpi_add_piece(sys, size(indices, kind=c_size_t), indices, c_funloc(grad), &
                                        c_funloc(energy), u), sys, status)
        end if
    end subroutine

    recursive subroutine lpi_add_piece_i8(sys, indices, grad, energy, user, status)
        type(c_ptr), intent(in) :: sys
        integer(c_int64_t), intent(in) :: indices(:)
        procedure(lpi_gradient_fn) :: grad
        procedure(lpi_energy_fn) :: energy
        type(c_ptr), intent(in), optional :: user
        integer, intent(out), optional :: status
        if (indices_refused(indices, "lpi_add_piece: indices", status)) return
        call lpi_add_piece_i4(sys, int(indices, c_int32_t), grad, energy, user, status)
    end subroutine

    recursive subroutine lpi_add_casimir(sys, fn, user, status)
        type(c_ptr), intent(in) :: sys
        procedure(lpi_casimir_fn) :: fn
        type(c_ptr), intent(in), optional :: user
        integer, intent(out), optional :: status
        type(c_ptr) :: u
        u = c_null_ptr
        if (present(user)) u = user
        call finish(c_lpi_add_casimir(sys, c_funloc(fn), u), sys, status)
    end subroutine

    recursive subroutine lpi_poisson_rank(sys, x, rank, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(in) :: x(:)
        integer, intent(out) :: rank
        integer, intent(out), optional :: status
        integer(c_size_t) :: r
        integer(c_int) :: st
        real(c_double) :: none(1) = 0  ! saved: read by nobody (a length of 0)
        r = 0
        if (size(x) == 0) then
            st = c_lpi_poisson_rank(sys, none, 0_c_size_t, r)
        else
            st = c_lpi_poisson_rank(sys, x, size(x, kind=c_size_t), r)
        end if
        if (size_fits(r, rank, "lpi_poisson_rank: rank", status)) call finish(st, sys, status)
    end subroutine

    recursive subroutine lpi_moments_create(sys, status)
        type(c_ptr), intent(out) :: sys
        integer, intent(out), optional :: status
        call finish(c_lpi_moments_create(sys), c_null_ptr, status)
    end subroutine

    recursive subroutine lpi_moments_add_product_piece(sys, h, dh, user, status)
        type(c_ptr), intent(in) :: sys
        procedure(lpi_scalar_fn) :: h, dh
        type(c_ptr), intent(in), optional :: user
        integer, intent(out), optional :: status
        type(c_ptr) :: u
        u = c_null_ptr
        if (present(user)) u = user
        call finish(c_lpi_moments_add_product_piece(sys, c_funloc(h), c_funloc(dh), u), sys, status)
    end subroutine

    ! ---- sine-Euler, threads, FFTW wisdom ---------------------------------------------

    recursive subroutine lpi_sine_euler_create(sys, n, status)
        type(c_ptr), intent(out) :: sys
        integer, intent(in) :: n
        integer, intent(out), optional :: status
        sys = c_null_ptr
        if (int32_refused(int(n, c_int64_t), "lpi_sine_euler_create: n", status)) return
        call finish(c_lpi_sine_euler_create(sys, int(n, c_int32_t)), c_null_ptr, status)
    end subroutine

    recursive subroutine lpi_sine_euler_size(sys, n, status)
        type(c_ptr), intent(in) :: sys
        integer, intent(out) :: n
        integer, intent(out), optional :: status
        integer(c_int32_t) :: m
        integer(c_int) :: st
        m = 0
        st = c_lpi_sine_euler_size(sys, m)
        n = int(m)
        call finish(st, sys, status)
    end subroutine

    ! w(a, b) is mode (a, b) mod N (lower bounds 0 or 1 alike: position counts).
    recursive subroutine lpi_sine_euler_set_modes(sys, w, status)
        type(c_ptr), intent(in) :: sys
        complex(c_double_complex), intent(in) :: w(:, :)
        integer, intent(out), optional :: status
        real(c_double), allocatable :: buf(:)
        integer(c_int64_t) :: a, b, n1, n2, q  ! 2 N^2 passes a default integer from N = 32769
        if (shape_refused(sys, shape(w), "lpi_sine_euler_set_modes: w", status)) return
        n1 = size(w, 1, kind=c_int64_t)
        n2 = size(w, 2, kind=c_int64_t)
        allocate (buf(2 * n1 * n2))
        do a = 1, n1
            do b = 1, n2
                q = 2 * ((a - 1) * n2 + (b - 1))
                buf(q + 1) = real(w(a, b), c_double)
                buf(q + 2) = aimag(w(a, b))
            end do
        end do
        call finish(c_lpi_sine_euler_set_modes(sys, buf, size(buf, kind=c_size_t)), sys, status)
    end subroutine

    recursive subroutine lpi_sine_euler_get_modes(sys, w, status)
        type(c_ptr), intent(in) :: sys
        complex(c_double_complex), intent(inout) :: w(:, :)
        integer, intent(out), optional :: status
        real(c_double), allocatable :: buf(:)
        integer(c_int) :: st
        integer(c_int64_t) :: a, b, n1, n2, q  ! as in lpi_sine_euler_set_modes
        if (shape_refused(sys, shape(w), "lpi_sine_euler_get_modes: w", status)) return
        n1 = size(w, 1, kind=c_int64_t)
        n2 = size(w, 2, kind=c_int64_t)
        allocate (buf(2 * n1 * n2))
        st = c_lpi_sine_euler_get_modes(sys, buf, size(buf, kind=c_size_t))
        if (st == LPI_OK) then
            do a = 1, n1
                do b = 1, n2
                    q = 2 * ((a - 1) * n2 + (b - 1))
                    w(a, b) = cmplx(buf(q + 1), buf(q + 2), c_double_complex)
                end do
            end do
        end if
        call finish(st, sys, status)
    end subroutine

    ! w(a, b) is the vorticity at (2 pi a / N, 2 pi b / N).
    recursive subroutine lpi_sine_euler_set_grid(sys, w, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(in) :: w(:, :)
        integer, intent(out), optional :: status
        real(c_double), allocatable :: t(:, :)
        if (shape_refused(sys, shape(w), "lpi_sine_euler_set_grid: w", status)) return
        allocate (t(size(w, 2), size(w, 1)))
        t = transpose(w)
        call finish(c_lpi_sine_euler_set_grid(sys, t, size(t, kind=c_size_t)), sys, status)
    end subroutine

    recursive subroutine lpi_sine_euler_get_grid(sys, w, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(inout) :: w(:, :)
        integer, intent(out), optional :: status
        real(c_double), allocatable :: t(:, :)
        integer(c_int) :: st
        if (shape_refused(sys, shape(w), "lpi_sine_euler_get_grid: w", status)) return
        allocate (t(size(w, 2), size(w, 1)))
        st = c_lpi_sine_euler_get_grid(sys, t, size(t, kind=c_size_t))
        if (st == LPI_OK) w = transpose(t)
        call finish(st, sys, status)
    end subroutine

    recursive subroutine lpi_sine_euler_enstrophy(sys, e, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(out) :: e
        integer, intent(out), optional :: status
        call finish(c_lpi_sine_euler_enstrophy(sys, e), sys, status)
    end subroutine

    ! traces(k) = (1/N) tr W^k for k = 1 .. size(traces).
    recursive subroutine lpi_sine_euler_casimir_traces(sys, traces, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(inout) :: traces(:)
        integer, intent(out), optional :: status
        if (int32_refused(size(traces, kind=c_int64_t), "lpi_sine_euler_casimir_traces: size(traces)", &
                          status)) return
        call finish(c_lpi_sine_euler_casimir_traces(sys, size(traces, kind=c_int32_t), traces), &
                    sys, status)
    end subroutine

    recursive subroutine lpi_sine_euler_fft_floor_i4(sys, nsteps, seconds_per_step, transforms_per_step, status)
        type(c_ptr), intent(in) :: sys
        integer(c_int32_t), intent(in) :: nsteps
        real(c_double), intent(out) :: seconds_per_step, transforms_per_step
        integer, intent(out), optional :: status
        call lpi_sine_euler_fft_floor_i8(sys, int(nsteps, c_int64_t), seconds_per_step, transforms_per_step, &
                                         status)
    end subroutine

    recursive subroutine lpi_sine_euler_fft_floor_i8(sys, nsteps, seconds_per_step, transforms_per_step, status)
        type(c_ptr), intent(in) :: sys
        integer(c_int64_t), intent(in) :: nsteps
        real(c_double), intent(out) :: seconds_per_step, transforms_per_step
        integer, intent(out), optional :: status
        call finish(c_lpi_sine_euler_fft_floor(sys, nsteps, seconds_per_step, transforms_per_step), sys, status)
    end subroutine

    ! rigor: "estimate" (the default), "measure" or "patient".
    recursive subroutine lpi_sine_euler_set_planning(sys, rigor, status)
        type(c_ptr), intent(in) :: sys
        character(len=*), intent(in) :: rigor
        integer, intent(out), optional :: status
        if (nul_refused(rigor, "lpi_sine_euler_set_planning: rigor", status)) return
        call finish(c_lpi_sine_euler_set_planning(sys, c_string(rigor)), sys, status)
    end subroutine

    recursive subroutine lpi_sine_euler_get_planning(sys, rigor, status)
        type(c_ptr), intent(in) :: sys
        character(len=:), allocatable, intent(out) :: rigor
        integer, intent(out), optional :: status
        type(c_ptr) :: p
        integer(c_int) :: st
        p = c_null_ptr
        st = c_lpi_sine_euler_get_planning(sys, p)
        rigor = f_string(p)
        call finish(st, sys, status)
    end subroutine

    ! H = 1/2 sum lambda_n |w_n|^2 + sum conj(f_n) w_n: lambda(a, b) and
    ! f(a, b) belong to mode (a-1, b-1), as in lpi_sine_euler_set_modes; f
    ! absent for f = 0.
    recursive subroutine lpi_sine_euler_set_hamiltonian(sys, lambda, f, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(in) :: lambda(:, :)
        complex(c_double_complex), intent(in), optional :: f(:, :)
        integer, intent(out), optional :: status
        real(c_double), allocatable :: t(:, :)
        real(c_double), allocatable, target :: buf(:)
        integer(c_int64_t) :: a, b, n2, q  ! as in lpi_sine_euler_set_modes
        if (shape_refused(sys, shape(lambda), "lpi_sine_euler_set_hamiltonian: lambda", status)) return
        if (present(f)) then
            if (shape_refused(sys, shape(f), "lpi_sine_euler_set_hamiltonian: f", status)) return
        end if
        allocate (t(size(lambda, 2), size(lambda, 1)))
        t = transpose(lambda)
        if (.not. present(f)) then
            call finish(c_lpi_sine_euler_set_hamiltonian(sys, t, size(t, kind=c_size_t), c_null_ptr, &
                                                         0_c_size_t), sys, status)
            return
        end if
        n2 = size(f, 2, kind=c_int64_t)
        allocate (buf(2 * size(f, 1, kind=c_int64_t) * n2))
        do a = 1, size(f, 1, kind=c_int64_t)
            do b = 1, n2
                q = 2 * ((a - 1) * n2 + (b - 1))
                buf(q + 1) = real(f(a, b), c_double)
                buf(q + 2) = aimag(f(a, b))
            end do
        end do
        call finish(c_lpi_sine_euler_set_hamiltonian(sys, t, size(t, kind=c_size_t), c_loc(buf), &
                                                     size(buf, kind=c_size_t)), sys, status)
    end subroutine

    ! psi(a, b) is the stream function at (2 pi (a-1) / N, 2 pi (b-1) / N).
    recursive subroutine lpi_sine_euler_get_stream(sys, psi, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(inout) :: psi(:, :)
        integer, intent(out), optional :: status
        real(c_double), allocatable :: t(:, :)
        integer(c_int) :: st
        if (shape_refused(sys, shape(psi), "lpi_sine_euler_get_stream: psi", status)) return
        allocate (t(size(psi, 2), size(psi, 1)))
        st = c_lpi_sine_euler_get_stream(sys, t, size(t, kind=c_size_t))
        if (st == LPI_OK) psi = transpose(t)
        call finish(st, sys, status)
    end subroutine

    ! energy(k), enstrophy(k): shell k (k - 1/2 <= |n| < k + 1/2), k = 1 ..
    ! shells; the arrays need at least `shells` elements (LPI_ERR_SIZE, with
    ! shells set, otherwise).
    ! Both arrays empty: the query of the shell count (shells set, LPI_OK).
    recursive subroutine lpi_sine_euler_spectrum(sys, energy, enstrophy, shells, status)
        type(c_ptr), intent(in) :: sys
        real(c_double), intent(inout), target, contiguous :: energy(:), enstrophy(:)
        integer, intent(out) :: shells
        integer, intent(out), optional :: status
        integer(c_size_t) :: count
        integer(c_int) :: st
        type(c_ptr) :: e, z
        count = 0
        e = c_null_ptr
        z = c_null_ptr
        if (size(energy) > 0) e = c_loc(energy)
        if (size(enstrophy) > 0) z = c_loc(enstrophy)
        st = c_lpi_sine_euler_spectrum(sys, e, z, min(size(energy, kind=c_size_t), size(enstrophy, kind=c_size_t)), &
                                       count)
        if (size_fits(count, shells, "lpi_sine_euler_spectrum: shells", status)) call finish(st, sys, status)
    end subroutine

    recursive subroutine lpi_set_threads(sys, n, status)
        type(c_ptr), intent(in) :: sys
        integer, intent(in) :: n
        integer, intent(out), optional :: status
        if (int32_refused(int(n, c_int64_t), "lpi_set_threads: n", status)) return
        call finish(c_lpi_set_threads(sys, int(n, c_int32_t)), sys, status)
    end subroutine

    recursive subroutine lpi_fftw_wisdom_import_file(path, status)
        character(len=*), intent(in) :: path
        integer, intent(out), optional :: status
        if (nul_refused(path, "lpi_fftw_wisdom_import_file: path", status)) return
        call finish(c_lpi_fftw_wisdom_import_file(c_string(path)), c_null_ptr, status)
    end subroutine

    recursive subroutine lpi_fftw_wisdom_export_file(path, status)
        character(len=*), intent(in) :: path
        integer, intent(out), optional :: status
        if (nul_refused(path, "lpi_fftw_wisdom_export_file: path", status)) return
        call finish(c_lpi_fftw_wisdom_export_file(c_string(path)), c_null_ptr, status)
    end subroutine

    recursive subroutine lpi_fftw_wisdom_import_string(wisdom, status)
        character(len=*), intent(in) :: wisdom
        integer, intent(out), optional :: status
        if (nul_refused(wisdom, "lpi_fftw_wisdom_import_string: wisdom", status)) return
        call finish(c_lpi_fftw_wisdom_import_string(c_string(wisdom)), c_null_ptr, status)
    end subroutine

    ! The process's FFTW wisdom as one string.
    recursive subroutine lpi_fftw_wisdom_export_string(wisdom, status)
        character(len=:), allocatable, intent(out) :: wisdom
        integer, intent(out), optional :: status
        character(kind=c_char), allocatable, target :: buf(:)
        integer(c_size_t) :: length, q  ! not narrowed to a default integer
        integer(c_int) :: st
        integer :: tries
        wisdom = ""
        length = 0
        st = c_lpi_fftw_wisdom_export_string(c_null_ptr, 0_c_size_t, length)  ! a query of the length
        if (st == LPI_OK) then
            ! The wisdom is the process's: another thread planning between the
            ! query and the copy adds to it, and the buffer is then made again
            ! at the new length (given with LPI_ERR_SIZE).
            do tries = 1, 100
                if (allocated(buf)) deallocate (buf)
                allocate (buf(length + 1))
                st = c_lpi_fftw_wisdom_export_string(c_loc(buf), size(buf, kind=c_size_t), length)
                if (st /= LPI_ERR_SIZE) exit
            end do
            if (st == LPI_OK) then
                deallocate (wisdom)
                allocate (character(len=length) :: wisdom)
                do q = 1, length
                    wisdom(q:q) = buf(q)
                end do
            end if
        end if
        call finish(st, c_null_ptr, status)
    end subroutine

    ! ---- checkpoints ----------------------------------------------------------

    recursive subroutine lpi_save(sys, path, status)
        type(c_ptr), intent(in) :: sys
        character(len=*), intent(in) :: path
        integer, intent(out), optional :: status
        if (nul_refused(path, "lpi_save: path", status)) return
        call finish(c_lpi_save(sys, c_string(path)), sys, status)
    end subroutine

    recursive subroutine lpi_load(sys, path, status)
        type(c_ptr), intent(out) :: sys
        character(len=*), intent(in) :: path
        integer, intent(out), optional :: status
        sys = c_null_ptr
        if (nul_refused(path, "lpi_load: path", status)) return
        call finish(c_lpi_load(sys, c_string(path)), c_null_ptr, status)
    end subroutine

    ! The checkpoint in memory, as an allocatable byte array.
    recursive subroutine lpi_save_buffer(sys, bytes, status)
        type(c_ptr), intent(in) :: sys
        integer(c_int8_t), allocatable, target, intent(out) :: bytes(:)
        integer, intent(out), optional :: status
        integer(c_size_t) :: size
        integer(c_int) :: st
        st = c_lpi_save_buffer(sys, c_null_ptr, 0_c_size_t, size)
        if (st == LPI_OK) then
            allocate (bytes(size))
            st = c_lpi_save_buffer(sys, c_loc(bytes), size, size)
        else
            allocate (bytes(0))
        end if
        call finish(st, sys, status)
    end subroutine

    recursive subroutine lpi_load_buffer(sys, bytes, status)
        type(c_ptr), intent(out) :: sys
        ! contiguous: a strided or reversed section is copied in, so that the
        ! address C reads from holds the bytes in order.
        integer(c_int8_t), contiguous, target, intent(in) :: bytes(:)
        integer, intent(out), optional :: status
        integer(c_int8_t), target :: none(1) = 0  ! saved: read by nobody (a length of 0)
        if (size(bytes) == 0) then
            call finish(c_lpi_load_buffer(sys, c_loc(none), 0_c_size_t), c_null_ptr, status)
        else
            call finish(c_lpi_load_buffer(sys, c_loc(bytes), size(bytes, kind=c_size_t)), c_null_ptr, status)
        end if
    end subroutine

end module liepoisson
