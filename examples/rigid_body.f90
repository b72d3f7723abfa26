! The free rigid body from Fortran: a fourth-order splitting watched by an
! observer, which records the largest Casimir (|m|^2) deviation along the run;
! at the end the state is compared with the exact solution (Jacobi elliptic
! functions). Build against an installed liepoisson:
!   gfortran rigid_body.f90 $(pkg-config --cflags --libs liepoisson-fortran)
! Exits 0 when the Casimir was kept to round-off and the state agrees with the
! exact solution.
module rigid_body_watch
    use, intrinsic :: iso_c_binding
    use liepoisson
    implicit none
    real(c_double) :: casimir0 = 0, worst_drift = 0
    integer :: observations = 0
contains
    ! Called every 100 steps; reads the system (allowed), never changes it.
    integer(c_int) function watch(sys, step, t, user) bind(C)
        type(c_ptr), value :: sys, user
        integer(c_int64_t), value :: step
        real(c_double), value :: t
        real(c_double) :: c(1)
        call lpi_casimirs(sys, c)
        worst_drift = max(worst_drift, abs(c(1) - casimir0))
        observations = observations + 1
        watch = 0
    end function
end module

program rigid_body
    use rigid_body_watch
    implicit none
    type(c_ptr) :: body
    real(c_double) :: m(3), exact(3), c(1), h
    integer :: nsteps = 2000
    real(c_double), parameter :: dt = 0.005_c_double

    call lpi_rigid_body_create(body, 1.0_c_double, 2.0_c_double, 3.0_c_double)
    call lpi_set_method(body, "triple-jump-4")
    call lpi_set_state(body, [1.0_c_double, 0.5_c_double, -0.3_c_double])
    call lpi_casimirs(body, c)
    casimir0 = c(1)
    call lpi_rigid_body_exact(body, dt * nsteps, exact)  ! from the initial state
    call lpi_set_observer(body, 100, watch)
    call lpi_step(body, dt, nsteps)
    call lpi_get_state(body, m)
    call lpi_energy(body, h)
    print '(a, f6.2, a, i0, a)', "t = ", lpi_time(body), " (", observations, " observations)"
    print '(a, es9.2)', "largest Casimir drift:   ", worst_drift
    print '(a, es9.2)', "error against the exact: ", maxval(abs(m - exact))
    print '(a, f12.9)', "energy:                  ", h
    call lpi_destroy(body)
    if (observations /= nsteps / 100 .or. worst_drift > 1e-14_c_double * casimir0) stop 1
    if (maxval(abs(m - exact)) > 1e-9_c_double) stop 1
end program
