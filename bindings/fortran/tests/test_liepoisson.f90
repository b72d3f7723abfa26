! Test of the Fortran binding: statuses, the rigid body's Casimir, errors with
! state unchanged, refusals made in Fortran of what C cannot see, Fortran
! callbacks against the built-in model, sine-Euler (modes, grid
! orientation, Casimirs, array shapes) when the library has FFTW, and
! integers beyond C's 32 bits refused (test_fortran_integer8 builds this
! program and the module with -fdefault-integer-8).
module test_callbacks
    use, intrinsic :: iso_c_binding
    implicit none
    real(c_double), parameter :: inertia(3) = [1.0_c_double, 2.0_c_double, 3.0_c_double]
contains
    integer(c_int) function axis_grad(n, x, g, user) bind(C)
        integer(c_size_t), value :: n
        real(c_double), intent(in) :: x(n)
        real(c_double), intent(out) :: g(n)
        type(c_ptr), value :: user
        real(c_double), pointer :: inv
        call c_f_pointer(user, inv)
        g(1) = x(1) * inv
        axis_grad = 0
    end function
    integer(c_int) function axis_energy(n, x, h, user) bind(C)
        integer(c_size_t), value :: n
        real(c_double), intent(in) :: x(n)
        real(c_double), intent(out) :: h
        type(c_ptr), value :: user
        real(c_double), pointer :: inv
        call c_f_pointer(user, inv)
        h = 0.5_c_double * x(1)**2 * inv
        axis_energy = 0
    end function
    integer(c_int) function squared_norm(dim, x, out, user) bind(C)
        integer(c_size_t), value :: dim
        real(c_double), intent(in) :: x(dim)
        real(c_double), intent(out) :: out
        type(c_ptr), value :: user
        out = sum(x**2)
        squared_norm = 0
        if (c_associated(user)) squared_norm = 1  ! a failing callback when given any user pointer
    end function
    ! Counts its calls in user, stops at the second; its own handle refuses
    ! to change (LPI_ERR_BUSY) and to be destroyed.
    integer(c_int) function stop_second(sys, step, t, user) bind(C)
        use liepoisson, only: c_lpi_set_state, c_lpi_destroy, LPI_ERR_BUSY
        type(c_ptr), value :: sys
        integer(c_int64_t), value :: step
        real(c_double), value :: t
        type(c_ptr), value :: user
        integer(c_int), pointer :: calls
        real(c_double) :: x(3) = [9.0_c_double, 9.0_c_double, 9.0_c_double]
        call c_f_pointer(user, calls)
        calls = calls + 1
        if (c_lpi_set_state(sys, x, 3_c_size_t) /= LPI_ERR_BUSY) calls = calls + 100
        if (c_lpi_destroy(sys) /= LPI_ERR_BUSY) calls = calls + 100
        if (step /= 5_c_int64_t * calls .or. t <= 0) calls = calls + 100
        stop_second = merge(1, 0, calls == 2)
    end function
    ! Calls the wrappers (not the bind(C) interfaces) from inside lpi_step:
    ! lpi_step on another system (user), lpi_energy on its own handle (a
    ! read, allowed) and lpi_step on its own handle (LPI_ERR_BUSY). The module
    ! is built with -fcheck=recursion, which stops a nested call of a wrapper
    ! not declared recursive.
    integer(c_int) function step_another(sys, step, t, user) bind(C)
        use liepoisson, only: lpi_step, lpi_energy, LPI_OK, LPI_ERR_BUSY
        type(c_ptr), value :: sys
        integer(c_int64_t), value :: step
        real(c_double), value :: t
        type(c_ptr), value :: user
        type(c_ptr), pointer :: other
        real(c_double) :: h
        integer :: status, own
        call c_f_pointer(user, other)
        call lpi_step(other, 0.01_c_double, 2, status)
        call lpi_energy(sys, h, own)
        step_another = 0
        if (status /= LPI_OK .or. own /= LPI_OK .or. step < 0 .or. t < 0) step_another = 1
        call lpi_step(sys, 0.01_c_double, 1, own)
        if (own /= LPI_ERR_BUSY) step_another = 1
    end function
end module

program test_liepoisson
    use, intrinsic :: iso_c_binding
    use liepoisson
    use test_callbacks
    implicit none
    integer :: failures = 0

    call test_statuses()
    call test_rigid_body()
    call test_errors()
    call test_refusals()
    call test_generic()
    call test_sine_euler()
    call test_observer()
    call test_wide_integers()
    if (failures > 0) then
        print '(i0, a)', failures, " check(s) failed"
        stop 1
    end if
    print '(a)', "fortran binding: all checks passed"

contains

    subroutine check(ok, what)
        logical, intent(in) :: ok
        character(len=*), intent(in) :: what
        if (.not. ok) then
            failures = failures + 1
            print '(a, a)', "FAILED: ", what
        end if
    end subroutine

    subroutine test_observer()
        type(c_ptr) :: sys
        type(c_ptr), target :: other
        integer(c_int), target :: calls
        integer :: status
        real(c_double) :: m(3) = [1.0_c_double, 0.5_c_double, -0.3_c_double]
        call lpi_rigid_body_create(sys, 1.0_c_double, 2.0_c_double, 3.0_c_double)
        call lpi_set_state(sys, m)
        calls = 0
        call lpi_set_observer(sys, 5_c_int64_t, stop_second, c_loc(calls))  ! a 64-bit every, as C takes
        call lpi_step(sys, 0.01_c_double, 100, status)
        call check(status == LPI_STOPPED, "observer stops lpi_step with LPI_STOPPED")
        call check(calls == 2, "observer called twice, its own handle refused (BUSY)")
        call check(abs(lpi_time(sys) - 0.1_c_double) < 1e-15_c_double, "stopped at step 10")
        call lpi_step(sys, 0.01_c_double, 3)  ! LPI_STOPPED never stops a program; none here
        call lpi_set_observer(sys, 0)         ! removed
        call lpi_step(sys, 0.01_c_double, 100)
        call check(calls == 2, "observer removed")
        call lpi_destroy(sys)
        call check(.not. c_associated(sys), "destroy nulls the handle")
        ! Wrappers called from inside a wrapper's call (see step_another).
        call lpi_rigid_body_create(sys, 1.0_c_double, 2.0_c_double, 3.0_c_double)
        call lpi_rigid_body_create(other, 1.0_c_double, 2.0_c_double, 3.0_c_double)
        call lpi_set_state(sys, m)
        call lpi_set_state(other, m)
        call lpi_set_observer(sys, 1, step_another, c_loc(other))
        call lpi_step(sys, 0.01_c_double, 3, status)
        call check(status == LPI_OK, "an observer calls the wrappers on another handle and its own")
        call check(abs(lpi_time(other) - 0.06_c_double) < 1e-15_c_double, "the other system stepped")
        call lpi_destroy(sys)
        call lpi_destroy(other)
    end subroutine

    subroutine test_statuses()
        integer :: i
        logical :: found
        type(c_ptr) :: sys
        character(len=16) :: text
        call check(len(lpi_version_string()) >= 5, "version string")
        write (text, '(I0,".",I0,".",I0)') lpi_version_number() / 10000, &
            mod(lpi_version_number() / 100, 100), mod(lpi_version_number(), 100)
        call check(trim(text) == lpi_version_string(), "version number matches the string")
        call lpi_rigid_body_create(sys, 1.0_c_double, 2.0_c_double, 3.0_c_double)
        call check(lpi_kind(sys) == "rigid-body", "kind")
        call check(lpi_get_method(sys) == "leapfrog", "default method")
        call check(lpi_get_split(sys) == "casimir-shift", "default split")
        call lpi_set_method(sys, "strang")
        call lpi_set_split(sys, "axes")
        call check(lpi_get_method(sys) == "leapfrog", "an alias reads back as its name")
        call check(lpi_get_split(sys) == "axes", "split read back")
        call lpi_destroy(sys)
        call check(lpi_kind(sys) == "", "null handle has no kind")
        call check(lpi_status_name(LPI_OK) == "LPI_OK", "LPI_OK")
        call check(lpi_status_name(LPI_ERR_SIZE) == "LPI_ERR_SIZE", "LPI_ERR_SIZE")
        call check(lpi_status_name(LPI_ERR_CALLBACK) == "LPI_ERR_CALLBACK", "LPI_ERR_CALLBACK")
        call check(lpi_status_name(LPI_ERR_NO_CONVERGENCE) == "LPI_ERR_NO_CONVERGENCE", &
                   "LPI_ERR_NO_CONVERGENCE")
        call check(lpi_status_name(LPI_ERR_NO_CONVERGENCE - 100) == "LPI_UNKNOWN_STATUS", "unknown")
        call check(len(lpi_status_message(LPI_ERR_NULL)) > 0, "status message")
        found = .false.
        do i = 0, lpi_method_count() - 1
            if (lpi_method_name(i) == "leapfrog") then
                found = .true.
                call check(lpi_method_order(i) == 2, "leapfrog order")
                call check(lpi_method_is_poisson(i) == 1, "leapfrog is Poisson")
                call check(lpi_method_stages(i) == 1, "leapfrog stages")
                call check(len(lpi_method_reference(i)) > 0, "leapfrog reference")
            end if
        end do
        call check(found, "leapfrog listed")
        call check(lpi_method_name(lpi_method_count()) == "", "method out of range")
    end subroutine

    subroutine test_rigid_body()
        type(c_ptr) :: sys, copy, copy2
        real(c_double) :: m(3), m_copy(3), c0(1), c1(1), exact(3), h, short_m(2), spread_m(5)
        integer(c_int8_t), allocatable :: bytes(:), spread_bytes(:)
        integer :: flows, status
        call lpi_rigid_body_create(sys, 1.0_c_double, 2.0_c_double, 3.0_c_double)
        call check(lpi_dim(sys) == 3, "rigid body dim")
        call check(lpi_casimir_count(sys) == 1, "rigid body casimir count")
        call lpi_set_method(sys, "triple-jump-4")
        call lpi_set_state(sys, [1.0_c_double, 0.5_c_double, -0.3_c_double])
        call lpi_casimirs(sys, c0)
        call lpi_rigid_body_exact(sys, 100.0_c_double, exact)
        call lpi_step(sys, 0.01_c_double, 10000)
        call lpi_step(sys, 0.0_c_double + 0.01_c_double, 0_c_int64_t)
        call lpi_casimirs(sys, c1)
        call lpi_get_state(sys, m)
        call lpi_energy(sys, h)
        print '(a, es10.3, a, es10.3)', "rigid body, triple-jump-4, 1e4 steps: |m|^2 drift ", &
            abs(c1(1) - c0(1)) / c0(1), ", error vs exact ", maxval(abs(m - exact))
        call check(abs(c1(1) - c0(1)) < 1e-13_c_double * c0(1), "Casimir kept to round-off")
        call check(maxval(abs(m - exact)) < 1e-6_c_double, "agrees with the exact solution")
        call check(abs(lpi_time(sys) - 100.0_c_double) < 1e-9_c_double, "time")
        call lpi_set_composition(sys, [0.5_c_double, 0.5_c_double])
        call lpi_flows_per_step(sys, flows)
        call check(flows > 0, "flows per step")
        ! A checkpoint in memory resumes the trajectory bit for bit.
        call lpi_save_buffer(sys, bytes)
        call lpi_load_buffer(copy, bytes)
        call lpi_step(sys, 0.01_c_double, 100)
        call lpi_step(copy, 0.01_c_double, 100)
        call lpi_get_state(sys, m)
        call lpi_get_state(copy, m_copy)
        call check(all(m == m_copy), "checkpoint resumes bit for bit")
        call lpi_load_buffer(copy2, bytes(1:size(bytes) - 1), status)
        call check(status == LPI_ERR_FORMAT, "truncated checkpoint refused")
        ! A strided section holding the checkpoint loads (C was handed the
        ! address of its first element and read the gaps).
        allocate (spread_bytes(2 * size(bytes)))
        spread_bytes = 0
        spread_bytes(1::2) = bytes
        call lpi_load_buffer(copy2, spread_bytes(1::2), status)
        call check(status == LPI_OK, "checkpoint from a strided section")
        call lpi_get_state(copy2, m_copy)
        call lpi_destroy(copy2)
        ! The exact solution has 3 values: any other array is refused, not
        ! written past its end.
        call lpi_rigid_body_exact(sys, 1.0_c_double, short_m, status)
        call check(status == LPI_ERR_SIZE, "exact solution into 2 values refused")
        ! A failure leaves m as it was, a strided section too (gfortran passed
        ! C a temporary, copied back unwritten).
        spread_m = 99.0_c_double
        call lpi_rigid_body_exact(sys, ieee_nan(), spread_m(1::2), status)
        call check(status == LPI_ERR_NONFINITE, "exact solution at t = NaN refused")
        call check(all(spread_m == 99.0_c_double), "a failed exact solution leaves m as it was")
        call lpi_destroy(copy)
        call lpi_destroy(sys)
        call check(.not. c_associated(sys), "destroy nulls the handle")
        call lpi_destroy(sys)  ! no-op
    end subroutine

    subroutine test_errors()
        type(c_ptr) :: sys
        real(c_double) :: before(3), after(3)
        integer :: status
        character(len=:), allocatable :: msg
        call lpi_rigid_body_create(sys, -1.0_c_double, 1.0_c_double, 1.0_c_double, status)
        call check(status == LPI_ERR_INVALID, "negative inertia refused")
        call check(.not. c_associated(sys), "no handle after a failed create")
        call check(index(lpi_last_error(c_null_ptr), "lpi_rigid_body_create") > 0, "thread message")

        call lpi_pendulum_create(sys)
        call lpi_set_state(sys, [0.6_c_double, -0.8_c_double, 1.2_c_double])
        call lpi_step(sys, 0.1_c_double, 10)
        call lpi_get_state(sys, before)
        call lpi_set_state(sys, [1.0_c_double, 2.0_c_double], status)
        call check(status == LPI_ERR_SIZE, "wrong length: LPI_ERR_SIZE")
        msg = lpi_last_error(sys)
        call check(index(msg, "lpi_set_state") > 0, "message names lpi_set_state: "//msg)
        call lpi_step(sys, ieee_nan(), 1, status)
        call check(status == LPI_ERR_NONFINITE, "NaN dt: LPI_ERR_NONFINITE")
        call lpi_set_method(sys, "no-such-method   ", status)
        call check(status == LPI_ERR_INVALID, "unknown method")
        call check(index(lpi_last_error(sys), "no-such-method'") > 0, "trailing blanks trimmed")
        call lpi_set_threads(sys, 2, status)
        call check(status == LPI_ERR_UNSUPPORTED, "threads on the pendulum")
        ! An empty array constructor (passed by gfortran as a NULL address) is
        ! a length of 0, as an empty variable is: not a NULL pointer.
        call lpi_set_state(sys, [real(c_double) ::], status)
        call check(status == LPI_ERR_SIZE, "empty constructor: LPI_ERR_SIZE, not NULL")
        call lpi_set_composition(sys, [real(c_double) ::], status)
        call check(status == LPI_ERR_INVALID, "no weights: LPI_ERR_INVALID, not NULL")
        call lpi_get_state(sys, after)
        call check(all(before == after), "state unchanged after failed calls")
        call lpi_set_method(sys, "leapfrog   ")
        call lpi_set_split(sys, "standard-map")
        call lpi_set_implicit_options(sys, 1e-12_c_double, 50)
        call lpi_destroy(sys)
    end subroutine

    ! A NUL inside a string (C would read only the part before it) and a
    ! negative dim (int(dim, c_size_t) would wrap it) are refused before C is
    ! called: nothing changes, no file is written, no handle made.
    subroutine test_refusals()
        character(len=*), parameter :: path = "test_fortran_nul.ck"
        type(c_ptr) :: sys, copy
        integer :: status
        logical :: exists
        character(len=:), allocatable :: msg
        call lpi_rigid_body_create(sys, 1.0_c_double, 2.0_c_double, 3.0_c_double)
        call lpi_set_method(sys, "triple-jump-4")
        call lpi_set_method(sys, "leapfrog"//c_null_char//"garbage", status)
        call check(status == LPI_ERR_INVALID, "method name holding a NUL refused")
        call check(lpi_get_method(sys) == "triple-jump-4", "method unchanged")
        call lpi_set_split(sys, "axes"//c_null_char, status)
        call check(status == LPI_ERR_INVALID, "split name holding a NUL refused")
        call check(lpi_get_split(sys) == "casimir-shift", "split unchanged")
        call remove_file(path)
        call lpi_save(sys, path//c_null_char//".x", status)
        call check(status == LPI_ERR_INVALID, "lpi_save: path holding a NUL refused")
        inquire (file=path, exist=exists)
        call check(.not. exists, "lpi_save: nothing written at the path before the NUL")
        call lpi_save(sys, path)
        call lpi_load(copy, path//c_null_char//".x", status)
        call check(status == LPI_ERR_INVALID, "lpi_load: path holding a NUL refused")
        call check(.not. c_associated(copy), "lpi_load: no handle after the refusal")
        call remove_file(path)
        call lpi_destroy(sys)
        ! Refused before C: the thread's message is still the failed create's.
        call lpi_rigid_body_create(copy, -1.0_c_double, 1.0_c_double, 1.0_c_double, status)
        msg = lpi_last_error(c_null_ptr)
        call lpi_generic_create(copy, -1, [integer(c_int32_t) ::], [integer(c_int32_t) ::], &
                                [integer(c_int32_t) ::], [real(c_double) ::], status)
        call check(status == LPI_ERR_INVALID, "negative dim refused")
        call check(.not. c_associated(copy), "no handle after a negative dim")
        call check(lpi_last_error(c_null_ptr) == msg, "negative dim refused before C (not as 2^64 - 1): " &
                   //lpi_last_error(c_null_ptr))
    end subroutine

    subroutine remove_file(path)
        character(len=*), intent(in) :: path
        integer :: unit, ios
        open (newunit=unit, file=path, status="old", iostat=ios)
        if (ios == 0) close (unit, status="delete")
    end subroutine

    function ieee_nan() result(x)
        use, intrinsic :: ieee_arithmetic
        real(c_double) :: x
        x = ieee_value(x, ieee_quiet_nan)
    end function

    subroutine test_generic()
        type(c_ptr) :: gen, ref
        real(c_double), target, save :: inverse(3)
        real(c_double) :: xg(3), xr(3), c(1), c2(2), worst
        integer(c_int32_t) :: k
        integer :: rank, q, status
        integer, target :: anything
        inverse = 1.0_c_double / inertia
        call lpi_generic_create(gen, 3, [0, 0, 1], [1, 2, 2], [2, 1, 0], &
                                [-1.0_c_double, 1.0_c_double, -1.0_c_double])
        do k = 0, 2
            call lpi_add_piece(gen, [k], axis_grad, axis_energy, c_loc(inverse(k + 1)))
        end do
        call lpi_add_casimir(gen, squared_norm)
        call lpi_poisson_rank(gen, [1.0_c_double, 0.5_c_double, -0.3_c_double], rank)
        call check(rank == 2, "so(3) Poisson rank 2")
        call lpi_rigid_body_create(ref, inertia(1), inertia(2), inertia(3))
        call lpi_set_split(ref, "axes")
        call lpi_set_state(gen, [1.0_c_double, 0.5_c_double, -0.3_c_double])
        call lpi_set_state(ref, [1.0_c_double, 0.5_c_double, -0.3_c_double])
        worst = 0
        do q = 1, 10
            call lpi_step(gen, 0.05_c_double, 100)
            call lpi_step(ref, 0.05_c_double, 100)
            call lpi_get_state(gen, xg)
            call lpi_get_state(ref, xr)
            worst = max(worst, maxval(abs(xg - xr)))
        end do
        print '(a, es10.3)', "generic so(3) with Fortran callbacks vs built-in, 1000 steps: ", worst
        call check(worst < 5e-13_c_double, "generic matches built-in")
        call lpi_casimirs(gen, c)
        call check(abs(c(1) - 1.34_c_double) < 1e-13_c_double, "user Casimir")
        ! A callback reporting failure: LPI_ERR_CALLBACK.
        call lpi_add_casimir(gen, squared_norm, c_loc(anything))
        call lpi_casimirs(gen, c2, status)
        call check(status == LPI_ERR_CALLBACK, "failing callback: LPI_ERR_CALLBACK")
        call lpi_destroy(gen)
        call lpi_generic_create(gen, 3, [0, 0], [1, 2], [2], [1.0_c_double], status)
        call check(status == LPI_ERR_SIZE, "bracket arrays of different lengths")
        call check(.not. c_associated(gen), "a failed create leaves no handle")
        call lpi_destroy(ref)
        call lpi_moments_create(ref)
        call check(lpi_casimir_count(ref) == 2, "moments: two Casimirs")
        call lpi_destroy(ref)
    end subroutine

    ! 64-bit index arrays whatever the default kind; with a default integer
    ! of 8 bytes, default integers beyond C's 32-bit int refused before C,
    ! not narrowed to another number (2**32 + 3 to 3), and literal index
    ! arrays (64-bit then) taken. The big values are computed at run time,
    ! so that a 4-byte build compiles them.
    subroutine test_wide_integers()
        real(c_double), target, save :: inverse(3)
        type(c_ptr) :: sys, gen
        integer :: two32, status
        character(len=:), allocatable :: msg
        inverse = 1.0_c_double / inertia
        print '(a, i0, a)', "default integer: ", digits(0) + 1, " bits"
        call lpi_generic_create(gen, 3, [0_c_int64_t, 0_c_int64_t, 1_c_int64_t], &
                                [1_c_int64_t, 2_c_int64_t, 2_c_int64_t], [2_c_int64_t, 1_c_int64_t, 0_c_int64_t], &
                                [-1.0_c_double, 1.0_c_double, -1.0_c_double], status)
        call check(status == LPI_OK .and. lpi_dim(gen) == 3, "64-bit bracket index arrays")
        call lpi_add_piece(gen, [0_c_int64_t], axis_grad, axis_energy, c_loc(inverse(1)), status)
        call check(status == LPI_OK, "64-bit piece index array")
        call lpi_add_piece(gen, [1_c_int64_t, 2_c_int64_t**32 + 2], axis_grad, axis_energy, &
                           c_loc(inverse(2)), status)
        call check(status == LPI_ERR_INVALID, "piece index 2**32 + 2 refused, not taken as 2")
        call lpi_destroy(gen)
        call lpi_generic_create(gen, 3, [0_c_int64_t], [1_c_int64_t], [2_c_int64_t**32 + 2], [1.0_c_double], &
                                status)
        call check(status == LPI_ERR_INVALID .and. .not. c_associated(gen), &
                   "bracket index 2**32 + 2 refused, no handle")
        if (digits(0) <= 31) return
        two32 = 2
        two32 = two32**32

        ! Refused before C: the thread's and the handle's messages stay.
        call lpi_rigid_body_create(sys, -1.0_c_double, 1.0_c_double, 1.0_c_double, status)
        msg = lpi_last_error(c_null_ptr)
        call lpi_sine_euler_create(sys, two32 + 3, status)
        call check(status == LPI_ERR_INVALID, "sine-Euler N = 2**32 + 3 refused, not made N = 3")
        call check(.not. c_associated(sys), "no handle after N = 2**32 + 3")
        call check(lpi_last_error(c_null_ptr) == msg, "N = 2**32 + 3 refused before C")
        call lpi_rigid_body_create(sys, 1.0_c_double, 2.0_c_double, 3.0_c_double)
        call lpi_set_method(sys, "no-such-method", status)
        msg = lpi_last_error(sys)
        call lpi_set_threads(sys, two32 + 1, status)
        call check(status == LPI_ERR_INVALID, "2**32 + 1 threads refused, not set to 1")
        call check(lpi_last_error(sys) == msg, "threads refused before C (the count unchanged)")
        ! 2**32 + 1 iterations taken as 1 would leave implicit-midpoint
        ! unconverged at 1e-13.
        call lpi_set_method(sys, "implicit-midpoint")
        call lpi_set_state(sys, [1.0_c_double, 0.5_c_double, -0.3_c_double])
        call lpi_set_implicit_options(sys, 1e-13_c_double, two32 + 1, status)
        call check(status == LPI_ERR_INVALID, "2**32 + 1 implicit iterations refused")
        call lpi_step(sys, 0.01_c_double, 10, status)
        call check(status == LPI_OK, "implicit options unchanged (100 iterations converge)")
        call lpi_destroy(sys)
        ! Out of range, not wrapped to method 0 or to a known status.
        call check(lpi_method_name(two32) == "", "method 2**32 has no name")
        call check(lpi_method_order(two32) == -1 .and. lpi_method_is_poisson(two32) == -1 .and. &
                   lpi_method_stages(two32) == -1 .and. lpi_method_reference(two32) == "", &
                   "method 2**32 out of range")
        call check(lpi_status_name(two32 + LPI_ERR_SIZE) == "LPI_UNKNOWN_STATUS", "status 2**32 - 3 unknown")
        call check(lpi_status_message(two32 + LPI_ERR_SIZE) == lpi_status_message(-1000), &
                   "status 2**32 - 3: the unknown status's message")
        ! Literal index arrays are 64-bit here.
        call lpi_generic_create(gen, 3, [0, 0, 1], [1, 2, 2], [2, 1, 0], &
                                [-1.0_c_double, 1.0_c_double, -1.0_c_double], status)
        call check(status == LPI_OK, "literal bracket index arrays")
        call lpi_add_piece(gen, [0], axis_grad, axis_energy, c_loc(inverse(1)), status)
        call check(status == LPI_OK, "literal piece index array")
        call lpi_add_piece(gen, [1, two32 + 2], axis_grad, axis_energy, c_loc(inverse(2)), status)
        call check(status == LPI_ERR_INVALID, "default piece index 2**32 + 2 refused")
        call lpi_destroy(gen)
    end subroutine

    subroutine test_sine_euler()
        integer, parameter :: n = 7
        real(c_double), parameter :: pi = 3.14159265358979323846_c_double
        type(c_ptr) :: sys
        complex(c_double_complex) :: w(0:n - 1, 0:n - 1), back(0:n - 1, 0:n - 1), s
        real(c_double) :: grid(0:n - 1, 0:n - 1), grid2(0:n - 1, 0:n - 1), t0(4), t1(4), e
        real(c_double) :: lambda(0:n - 1, 0:n - 1), energy(8), enstrophy(8), no_values(0), h, seconds, transforms
        character(len=*), parameter :: wisdom_path = "test_fortran_nul.wisdom"
        integer :: status, a, b, m1, m2, size_n, shells
        logical :: exists
        character(len=:), allocatable :: wisdom
        call lpi_sine_euler_create(sys, n, status)
        if (status == LPI_ERR_UNSUPPORTED) then
            print '(a)', "sine-Euler: library built without FFTW, skipped"
            return
        end if
        call check(status == LPI_OK, "sine-Euler create")
        call lpi_sine_euler_size(sys, size_n)
        call check(size_n == n, "sine-Euler size")
        call lpi_sine_euler_get_planning(sys, wisdom)
        call check(wisdom == "estimate", "default planning")
        call lpi_sine_euler_set_planning(sys, "measure")
        call lpi_sine_euler_get_planning(sys, wisdom)
        call check(wisdom == "measure", "planning read back")
        call lpi_sine_euler_set_planning(sys, "exhaustive", status)
        call check(status == LPI_ERR_INVALID, "unknown planning refused")
        call lpi_sine_euler_set_planning(sys, "patient"//c_null_char//"x", status)
        call check(status == LPI_ERR_INVALID, "planning holding a NUL refused")
        call lpi_sine_euler_get_planning(sys, wisdom)
        call check(wisdom == "measure", "planning unchanged")
        call random_seed()
        call random_number(grid)
        grid = grid - 0.5_c_double
        call lpi_sine_euler_set_grid(sys, grid)
        call lpi_sine_euler_get_modes(sys, w)
        do a = 0, n - 1
            do b = 0, n - 1
                call check(abs(w(a, b) - conjg(w(modulo(-a, n), modulo(-b, n)))) < 1e-14_c_double, &
                           "modes Hermitian")
            end do
        end do
        ! Orientation: grid(a, b) = sum_m w(m1, m2) exp(i (m1 x_a + m2 y_b)).
        s = 0
        do m1 = 0, n - 1
            do m2 = 0, n - 1
                s = s + w(m1, m2) * exp(cmplx(0, 2 * pi * (m1 * 1 + m2 * 3) / n, c_double_complex))
            end do
        end do
        call check(abs(s - grid(1, 3)) < 1e-12_c_double, "grid(a, b) is at (2 pi a/N, 2 pi b/N)")
        call lpi_sine_euler_set_modes(sys, w)
        call lpi_sine_euler_get_modes(sys, back)
        call check(all(back == w), "modes round trip")
        call lpi_sine_euler_get_grid(sys, grid2)
        call check(maxval(abs(grid2 - grid)) < 1e-13_c_double, "grid round trip")
        call lpi_sine_euler_casimir_traces(sys, t0)
        call lpi_sine_euler_enstrophy(sys, e)
        call lpi_step(sys, 0.01_c_double, 50)
        call lpi_sine_euler_casimir_traces(sys, t1)
        print '(a, es10.3)', "sine-Euler N = 7, 50 leapfrog steps: max tr W^k drift ", maxval(abs(t1 - t0))
        call check(maxval(abs(t1 - t0)) < 1e-12_c_double * max(1.0_c_double, maxval(abs(t0))), &
                   "sine-Euler Casimirs kept")
        back(1, 2) = back(1, 2) + (0.0_c_double, 0.5_c_double)
        call lpi_sine_euler_set_modes(sys, back, status)
        call check(status == LPI_ERR_INVALID, "non-Hermitian modes refused")
        ! SQG: lambda = 1/|m|; lpi_energy is then that H, and its shells add up to it.
        do a = 0, n - 1
            do b = 0, n - 1
                m1 = merge(a - n, a, a > n / 2)
                m2 = merge(b - n, b, b > n / 2)
                lambda(a, b) = 0
                if (a /= 0 .or. b /= 0) lambda(a, b) = 1 / sqrt(real(m1 * m1 + m2 * m2, c_double))
            end do
        end do
        call lpi_sine_euler_set_hamiltonian(sys, lambda)
        call lpi_sine_euler_get_modes(sys, w)
        call lpi_energy(sys, e)
        h = 0.5_c_double * sum(lambda * abs(w)**2)
        call check(abs(e - h) < 1e-14_c_double, "SQG energy is 1/2 sum |w|^2 / |m|")
        call lpi_sine_euler_spectrum(sys, no_values, no_values, shells, status)
        call check(status == LPI_OK .and. shells == 4, "two empty arrays ask for the shell count")
        call lpi_sine_euler_spectrum(sys, energy, enstrophy, shells)
        call check(shells == 4, "N = 7 has 4 shells (|m| up to 3 sqrt 2)")
        call lpi_sine_euler_fft_floor(sys, 2_c_int64_t, seconds, transforms)
        call check(seconds > 0 .and. transforms > 0, "the FFT floor, 64-bit step count")
        call check(abs(sum(energy(1:shells)) - e) < 1e-14_c_double, "energy shells add up to H")
        call lpi_sine_euler_get_stream(sys, grid2)
        lambda(0, 1) = 2
        call lpi_sine_euler_set_hamiltonian(sys, lambda, status=status)
        call check(status == LPI_ERR_INVALID, "lambda not symmetric refused")
        call lpi_energy(sys, h)
        call check(h == e, "refused lambda changes nothing")
        call lpi_fftw_wisdom_export_string(wisdom)
        call check(index(wisdom, "fftw") > 0, "wisdom exported")
        call lpi_fftw_wisdom_import_string(wisdom)
        call lpi_fftw_wisdom_import_string("not wisdom", status)
        call check(status == LPI_ERR_INVALID, "bad wisdom refused")
        call lpi_fftw_wisdom_import_string(wisdom//c_null_char//"x", status)
        call check(status == LPI_ERR_INVALID, "wisdom holding a NUL refused")
        call remove_file(wisdom_path)
        call lpi_fftw_wisdom_export_file(wisdom_path//c_null_char//".x", status)
        call check(status == LPI_ERR_INVALID, "wisdom export: path holding a NUL refused")
        inquire (file=wisdom_path, exist=exists)
        call check(.not. exists, "wisdom export: nothing written at the path before the NUL")
        call lpi_fftw_wisdom_export_file(wisdom_path)
        call lpi_fftw_wisdom_import_file(wisdom_path//c_null_char//".x", status)
        call check(status == LPI_ERR_INVALID, "wisdom import: path holding a NUL refused")
        call remove_file(wisdom_path)
        call test_sine_euler_shapes(sys, n)
        call lpi_destroy(sys)
    end subroutine

    ! Arrays must be N x N: C sees only the element count, which 49 x 1 and
    ! 1 x 49 share with 7 x 7. Refused with LPI_ERR_SIZE, the system and the
    ! output untouched.
    subroutine test_sine_euler_shapes(sys, n)
        type(c_ptr), intent(in) :: sys
        integer, intent(in) :: n
        real(c_double), parameter :: mark = -7
        real(c_double) :: grid(n, n), grid2(n, n), lambda(n, n), flat(n * n, 1), e, e2
        complex(c_double_complex) :: w(n, n), w2(n, n), mflat(1, n * n)
        integer :: status
        call lpi_sine_euler_get_grid(sys, grid)
        call lpi_sine_euler_get_modes(sys, w)
        call lpi_energy(sys, e)
        flat = reshape(2 * grid, [n * n, 1])
        call lpi_sine_euler_set_grid(sys, flat, status)
        call check(status == LPI_ERR_SIZE, "set_grid: 49 x 1 refused")
        mflat = reshape(2 * w, [1, n * n])
        call lpi_sine_euler_set_modes(sys, mflat, status)
        call check(status == LPI_ERR_SIZE, "set_modes: 1 x 49 refused")
        lambda = 1
        call lpi_sine_euler_set_hamiltonian(sys, reshape(lambda, [n * n, 1]), status=status)
        call check(status == LPI_ERR_SIZE, "set_hamiltonian: lambda 49 x 1 refused")
        mflat = 0
        call lpi_sine_euler_set_hamiltonian(sys, lambda, mflat, status)
        call check(status == LPI_ERR_SIZE, "set_hamiltonian: f 1 x 49 refused")
        call lpi_sine_euler_get_grid(sys, grid2)
        call lpi_sine_euler_get_modes(sys, w2)
        call lpi_energy(sys, e2)
        call check(all(grid2 == grid) .and. all(w2 == w) .and. e2 == e, "refused shapes change nothing")
        flat = mark
        call lpi_sine_euler_get_grid(sys, flat, status)
        call check(status == LPI_ERR_SIZE .and. all(flat == mark), "get_grid: 49 x 1 refused, untouched")
        call lpi_sine_euler_get_stream(sys, flat, status)
        call check(status == LPI_ERR_SIZE .and. all(flat == mark), "get_stream: 49 x 1 refused, untouched")
        mflat = mark
        call lpi_sine_euler_get_modes(sys, mflat, status)
        call check(status == LPI_ERR_SIZE .and. all(mflat == mark), "get_modes: 1 x 49 refused, untouched")
    end subroutine

end program
