"""What the binding's tests share: the numpy module (None in list mode), the
so(3) brackets, a rigid body in a fixed state, results as plain lists."""
import liepoisson as lp

np = lp.np
SO3 = [(0, 1, 2, -1.0), (0, 2, 1, 1.0), (1, 2, 0, -1.0)]


def as_list(a):
    return [float(v) for v in (a.tolist() if np is not None and isinstance(a, np.ndarray) else a)]


def rigid_body():
    b = lp.RigidBody(1.0, 2.0, 3.0)
    b.state = [1.0, 0.5, -0.3]
    return b
