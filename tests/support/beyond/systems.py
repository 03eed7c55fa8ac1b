"""Mechanical systems that are not in the built-in catalog, each a posted spec beside an
independently written reference (a hand-written Lagrangian and loads for sympy's
LagrangesMethod), the states to compare them at and a run to integrate.

The known-issue labels follow the engine work in progress ("issue 11"): 1 spring length sign,
2 dampers along their line, 3 equilibria with gyroscopic terms, 4 drive work for time-dependent
L, 5 stop conditions, 6 degenerate input, 7 deterministic derivations.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import sympy as sp
from sympy.physics.vector import ReferenceFrame, dynamicsymbols

from .reference import Reference, lagranges_reference, moving_point, symbols, t

G = 9.81
Interval = tuple[float, float]


@dataclass
class System:
    id: str
    spec: dict
    reference: Callable[[], Reference]
    #: Per coordinate, the intervals its random values are drawn from (one picked at random:
    #: two intervals put a spring on both sides of its anchor).
    q_ranges: list[list[Interval]]
    run: dict  # SimulationRequest fields: initial, t_end, fps
    u_range: Interval = (-2.0, 2.0)
    slow: bool = False
    #: test kind -> reason it is expected to fail today (pytest xfail, strict).
    known: dict[str, str] = field(default_factory=dict)
    #: Signed d of each spring along a line (ℓ = |d|): which side of its anchor it is on.
    spring_sides: Callable[[np.ndarray, dict], list[float]] | None = None

    def side(self, q) -> tuple[bool, ...]:
        return tuple(d >= 0 for d in self.spring_sides(np.asarray(q), self.parameters))

    @property
    def own_side(self) -> tuple[bool, ...]:
        init = self.spec.get("initial", {})
        return self.side([init.get(n, 0.0) for n in self.spec["coordinates"]])

    @property
    def parameters(self) -> dict[str, float]:
        return dict(self.spec["parameters"])

    def states(self, rng: np.random.Generator, count: int = 6):
        out = []
        for _ in range(count):
            q = []
            for intervals in self.q_ranges:
                lo, hi = intervals[rng.integers(len(intervals))]
                q.append(rng.uniform(lo, hi))
            u = rng.uniform(*self.u_range, size=len(q))
            out.append((rng.uniform(0.0, 3.0), np.array(q), u))
        return out


def both_sides(lo: float, hi: float) -> list[Interval]:
    return [(-hi, -lo), (lo, hi)]


ANY: list[Interval] = [(-2.0, 2.0)]
BOTH = both_sides(0.2, 2.5)


def kinetic(m, *coords) -> sp.Expr:
    return m * sum(c.diff(t) ** 2 for c in coords) / 2


def gravity_down(axis: str = "y") -> dict:
    return {"acceleration": "g", "direction": [0, 0, -1] if axis == "z" else [0, -1, 0]}


# --- pendulum chains ---------------------------------------------------------------------


def chain_spec(n: int, masses: list[str], lengths: list[str], params: dict) -> dict:
    bodies = []
    for i in range(n):
        position = {
            "frame": "N",
            "components": [f"{lengths[i]}*sin(a{i + 1})", f"-{lengths[i]}*cos(a{i + 1})", 0],
        }
        if i:
            position["from"] = f"bob{i}"
        bodies.append({"name": f"bob{i + 1}", "mass": masses[i], "position": position})
    return {
        "title": f"{n}-link pendulum",
        "coordinates": [f"a{i + 1}" for i in range(n)],
        "parameters": params,
        "bodies": bodies,
        "gravity": gravity_down(),
    }


def chain_reference(n: int, masses: list[str], lengths: list[str]) -> Callable[[], Reference]:
    def build() -> Reference:
        q = list(dynamicsymbols(" ".join(f"a{i + 1}" for i in range(n)), seq=True))
        m = [sp.Symbol(s, real=True) for s in masses]
        ls = [sp.Symbol(s, real=True) for s in lengths]
        g = sp.Symbol("g", real=True)
        x = y = sp.S.Zero
        T = V = sp.S.Zero
        for i in range(n):
            x += ls[i] * sp.sin(q[i])
            y -= ls[i] * sp.cos(q[i])
            T += kinetic(m[i], x, y)
            V += m[i] * g * y
        params = sorted(set(m) | set(ls) | {g}, key=str)
        return lagranges_reference(T - V, q, params, ReferenceFrame("N"))

    return build


def chain(id_: str, n: int, distinct: bool, run: dict, slow: bool = False) -> System:
    if distinct:
        masses = [f"m{i + 1}" for i in range(n)]
        lengths = [f"l{i + 1}" for i in range(n)]
        params = {f"m{i + 1}": 1.0 - 0.15 * i for i in range(n)}
        params |= {f"l{i + 1}": 1.0 - 0.1 * i for i in range(n)}
    else:
        masses, lengths = ["m"] * n, ["l"] * n
        params = {"m": 0.7, "l": 0.5}
    params["g"] = G
    return System(
        id_,
        chain_spec(n, masses, lengths, params),
        chain_reference(n, masses, lengths),
        [ANY] * n,
        run,
        slow=slow,
    )


# --- rigid bodies in three Euler rotations ------------------------------------------------

EULER_FRAMES = [
    {"name": "A", "parent": "N", "axis": "z", "angle": "phi"},
    {"name": "B", "parent": "A", "axis": "x", "angle": "theta"},
    {"name": "C", "parent": "B", "axis": "z", "angle": "psi"},
]


def body_rates(phi, theta, psi):
    """ω in the body frame for z-x-z Euler angles (Goldstein 4.87), written out by hand."""
    dphi, dth, dpsi = phi.diff(t), theta.diff(t), psi.diff(t)
    return sp.Matrix(
        [
            dphi * sp.sin(theta) * sp.sin(psi) + dth * sp.cos(psi),
            dphi * sp.sin(theta) * sp.cos(psi) - dth * sp.sin(psi),
            dphi * sp.cos(theta) + dpsi,
        ]
    )


def heavy_top() -> System:
    spec = {
        "title": "Heavy symmetric top",
        "coordinates": ["phi", "theta", "psi"],
        "parameters": {"m": 1.0, "h": 0.3, "I1": 0.02, "I3": 0.04, "g": G},
        "frames": EULER_FRAMES,
        "bodies": [
            {
                "name": "top",
                "kind": "rigid_body",
                "mass": "m",
                "frame": "C",
                "position": {"frame": "C", "components": [0, 0, "h"]},
                "inertia": {"ixx": "I1", "iyy": "I1", "izz": "I3"},
            }
        ],
        "gravity": gravity_down("z"),
    }

    def build() -> Reference:
        phi, theta, psi = dynamicsymbols("phi theta psi")
        m, h, I1, I3, g = symbols("m h I1 I3 g")
        w = body_rates(phi, theta, psi)
        I1p = I1 + m * h**2  # about the pivot (parallel axes)
        L = I1p * (w[0] ** 2 + w[1] ** 2) / 2 + I3 * w[2] ** 2 / 2 - m * g * h * sp.cos(theta)
        return lagranges_reference(L, [phi, theta, psi], [m, h, I1, I3, g], ReferenceFrame("N"))

    run = {"initial": {"theta": 0.6, "phi_dot": 1.0, "psi_dot": 40.0}, "t_end": 2.0, "fps": 30}
    return System("heavy_symmetric_top", spec, build, [ANY, [(0.3, 2.8)], ANY], run)


#: A real body's central inertia: positive definite, principal moments within the triangle
#: inequality (izz was 3.5 > 1 + 2, a tensor no mass distribution has; the spec now refuses it).
FREE_INERTIA = {"ixx": 1.0, "iyy": 2.0, "izz": 2.5, "ixy": 0.1, "iyz": -0.05, "izx": 0.08}


def inertia_matrix(p: dict[str, float]) -> np.ndarray:
    return np.array(
        [
            [p["Ixx"], p["Ixy"], p["Izx"]],
            [p["Ixy"], p["Iyy"], p["Iyz"]],
            [p["Izx"], p["Iyz"], p["Izz"]],
        ]
    )


def free_body() -> System:
    params = {f"I{k[1:]}": v for k, v in FREE_INERTIA.items()}
    spec = {
        "title": "Torque-free asymmetric rigid body",
        "coordinates": ["phi", "theta", "psi"],
        "parameters": params,
        "frames": EULER_FRAMES,
        "bodies": [
            {
                "name": "body",
                "kind": "rigid_body",
                "mass": 1.0,
                "frame": "C",
                "position": [0, 0, 0],
                "inertia": {k: f"I{k[1:]}" for k in FREE_INERTIA},
            }
        ],
    }

    def build() -> Reference:
        phi, theta, psi = dynamicsymbols("phi theta psi")
        names = ["Ixx", "Iyy", "Izz", "Ixy", "Iyz", "Izx"]
        Ixx, Iyy, Izz, Ixy, Iyz, Izx = symbols(" ".join(names))
        w = body_rates(phi, theta, psi)
        inertia = sp.Matrix([[Ixx, Ixy, Izx], [Ixy, Iyy, Iyz], [Izx, Iyz, Izz]])
        L = (w.T * inertia * w)[0] / 2
        params = [Ixx, Iyy, Izz, Ixy, Iyz, Izx]
        return lagranges_reference(L, [phi, theta, psi], params, ReferenceFrame("N"))

    run = {
        "initial": {"theta": 1.1, "phi_dot": 0.7, "theta_dot": 0.4, "psi_dot": 1.3},
        "t_end": 4.0,
        "fps": 25,
    }
    return System("free_rigid_body", spec, build, [ANY, [(0.4, 2.7)], ANY], run, slow=True)


# --- rotating frames ----------------------------------------------------------------------


def turntable_particle(
    id_: str, omega: float, kx: float, ky: float, rest: float, known: dict | None = None
) -> System:
    """A particle on a turntable spinning at Omega about N.z, held by four springs whose far
    ends are fixed on the turntable at (±a, 0) and (0, ±a); x, y are measured on the table."""
    anchors = {
        "ax1": ("a", 0, "kx"),
        "ax2": ("-a", 0, "kx"),
        "ay1": (0, "a", "ky"),
        "ay2": (0, "-a", "ky"),
    }
    spec = {
        "title": "Particle on a turntable held by springs",
        "coordinates": ["x", "y"],
        "parameters": {"m": 1.0, "kx": kx, "ky": ky, "a": 1.0, "l0": rest, "Omega": omega},
        "frames": [{"name": "R", "parent": "N", "axis": "z", "angle": "Omega*t"}],
        "points": [
            {"name": name, "position": {"frame": "R", "components": [ax, ay, 0]}}
            for name, (ax, ay, _) in anchors.items()
        ],
        "bodies": [
            {"name": "puck", "mass": "m", "position": {"frame": "R", "components": ["x", "y", 0]}}
        ],
        "springs": [
            {"a": name, "b": "puck", "k": k, "rest_length": "l0"}
            for name, (_, _, k) in anchors.items()
        ],
    }

    def build() -> Reference:
        x, y = dynamicsymbols("x y")
        m, kx_, ky_, a, l0, Om = symbols("m kx ky a l0 Omega")
        c, s = sp.cos(Om * t), sp.sin(Om * t)

        def inertial(u, v):  # table coordinates -> N, by hand
            return u * c - v * s, u * s + v * c

        X, Y = inertial(x, y)
        V = sp.S.Zero
        for ax, ay, k in ((a, 0, kx_), (-a, 0, kx_), (0, a, ky_), (0, -a, ky_)):
            AX, AY = inertial(ax, ay)
            V += k * (sp.sqrt((X - AX) ** 2 + (Y - AY) ** 2) - l0) ** 2 / 2
        return lagranges_reference(
            kinetic(m, X, Y) - V, [x, y], [m, kx_, ky_, a, l0, Om], ReferenceFrame("N")
        )

    run = {"initial": {"x": 0.3, "y": -0.1, "x_dot": 0.2}, "t_end": 5.0, "fps": 20}
    return System(id_, spec, build, [[(-0.9, 0.9)]] * 2, run, known=known or {})


def rod_on_turntable() -> System:
    spec = {
        "title": "Rod pendulum on a turntable",
        "coordinates": ["theta"],
        "parameters": {"m": 1.0, "L": 1.0, "b": 0.3, "Omega": 2.0, "g": G},
        "frames": [
            {"name": "R", "parent": "N", "axis": "y", "angle": "Omega*t"},
            {"name": "P", "parent": "R", "axis": "z", "angle": "theta"},
        ],
        "points": [{"name": "pivot", "position": {"frame": "R", "components": ["b", 0, 0]}}],
        "bodies": [
            {
                "name": "rod",
                "kind": "rigid_body",
                "mass": "m",
                "frame": "P",
                "position": {"frame": "P", "components": [0, "-L/2", 0], "from": "pivot"},
                "inertia": {"ixx": "m*L**2/12", "iyy": 0, "izz": "m*L**2/12"},
            }
        ],
        "gravity": gravity_down(),
    }

    def build() -> Reference:
        (theta,) = dynamicsymbols("theta", seq=True)
        m, L, b, Om, g = symbols("m L b Omega g")
        N = ReferenceFrame("N")
        R = N.orientnew("R", "Axis", (Om * t, N.y))
        r_cm = (b + L / 2 * sp.sin(theta)) * R.x - L / 2 * sp.cos(theta) * R.y
        v = r_cm.dt(N)
        # ω in the rod's axes (x across, y along, z normal to its plane), by hand
        w_rod = sp.Matrix([Om * sp.sin(theta), Om * sp.cos(theta), theta.diff(t)])
        T = m * v.dot(v) / 2 + m * L**2 / 24 * (w_rod[0] ** 2 + w_rod[2] ** 2)
        V = m * g * r_cm.dot(N.y)
        return lagranges_reference(T - V, [theta], [m, L, b, Om, g], N)

    run = {"initial": {"theta": 0.4}, "t_end": 4.0, "fps": 25}
    return System("rod_pendulum_on_turntable", spec, build, [[(-3.0, 3.0)]], run)


def bead_on_parabola() -> System:
    spec = {
        "title": "Bead on a spinning parabola",
        "coordinates": ["r"],
        "parameters": {"m": 0.2, "a": 1.0, "Omega": 3.0, "g": G},
        "frames": [{"name": "H", "parent": "N", "axis": "y", "angle": "Omega*t"}],
        "bodies": [
            {
                "name": "bead",
                "mass": "m",
                "position": {"frame": "H", "components": ["r", "a*r**2", 0]},
            }
        ],
        "gravity": gravity_down(),
    }

    def build() -> Reference:
        (r,) = dynamicsymbols("r", seq=True)
        m, a, Om, g = symbols("m a Omega g")
        rd = r.diff(t)
        T = m / 2 * ((1 + 4 * a**2 * r**2) * rd**2 + Om**2 * r**2)
        return lagranges_reference(T - m * g * a * r**2, [r], [m, a, Om, g], ReferenceFrame("N"))

    run = {"initial": {"r": 0.5, "r_dot": -0.3}, "t_end": 5.0, "fps": 20}
    return System("bead_on_spinning_parabola", spec, build, [[(-1.5, 1.5)]], run)


# --- driven supports ----------------------------------------------------------------------


def driven_pendulum(id_: str, vertical: bool, params: dict, run: dict, known=None) -> System:
    drive = ["0", "a*cos(w*t)"] if vertical else ["a*cos(w*t)", "0"]
    spec = {
        "title": "Pendulum on a driven pivot",
        "coordinates": ["theta"],
        "parameters": params,
        "points": [{"name": "support", "position": [*drive, 0]}],
        "bodies": [
            {
                "name": "bob",
                "mass": "m",
                "position": {
                    "frame": "N",
                    "components": ["l*sin(theta)", "-l*cos(theta)", 0],
                    "from": "support",
                },
            }
        ],
        "gravity": gravity_down(),
    }

    def build() -> Reference:
        (theta,) = dynamicsymbols("theta", seq=True)
        m, rod, g, a, w = symbols("m l g a w")
        shift = a * sp.cos(w * t)
        x = rod * sp.sin(theta) + (0 if vertical else shift)
        y = -rod * sp.cos(theta) + (shift if vertical else 0)
        return lagranges_reference(
            kinetic(m, x, y) - m * g * y, [theta], [m, rod, g, a, w], ReferenceFrame("N")
        )

    return System(id_, spec, build, [[(-3.0, 3.0)]], run, known=known or {})


# --- springs and dashpots on a line and in the plane ----------------------------------------


def spring_anchor_line(known: dict) -> System:
    spec = {
        "title": "Mass on a line tied to an anchor, left of it",
        "coordinates": ["x"],
        "parameters": {"m": 1.0, "k": 10.0, "L0": 1.0},
        "points": [{"name": "anchor", "position": [0, 0, 0]}],
        "bodies": [{"name": "block", "mass": "m", "position": ["x", 0, 0]}],
        "springs": [{"a": "anchor", "b": "block", "k": "k", "rest_length": "L0"}],
        "initial": {"x": -1.3},
    }

    def build() -> Reference:
        (x,) = dynamicsymbols("x", seq=True)
        m, k, L0 = symbols("m k L0")
        V = k * (sp.sqrt(x**2) - L0) ** 2 / 2  # |x| − ℓ0, valid on both sides
        return lagranges_reference(kinetic(m, x) - V, [x], [m, k, L0], ReferenceFrame("N"))

    run = {"initial": {"x": -1.3, "x_dot": 0.4}, "t_end": 3.0, "fps": 20}
    return System(
        "spring_line_left_of_anchor",
        spec,
        build,
        [BOTH],
        run,
        known=known,
        spring_sides=lambda q, p: [q[0]],
    )


def spring_chain_walls(known: dict) -> System:
    """Three blocks between walls at 0 and 4, absolute coordinates; block 1 starts LEFT of
    the left wall, so its spring starts on the other side of its anchor."""
    spec = {
        "title": "Spring chain between walls",
        "coordinates": ["x1", "x2", "x3"],
        "parameters": {"m1": 1.0, "m2": 0.8, "m3": 1.2, "k": 8.0, "k2": 5.0, "L0": 1.0, "W": 4.0},
        "points": [
            {"name": "wall1", "position": [0, 0, 0]},
            {"name": "wall2", "position": ["W", 0, 0]},
        ],
        "bodies": [
            {"name": f"block{i}", "mass": f"m{i}", "position": [f"x{i}", 0, 0]} for i in (1, 2, 3)
        ],
        "springs": [
            {"a": "wall1", "b": "block1", "k": "k", "rest_length": "L0"},
            {"a": "block1", "b": "block2", "k": "k2", "rest_length": "L0"},
            {"a": "block2", "b": "block3", "k": "k2", "rest_length": "L0"},
            {"a": "block3", "b": "wall2", "k": "k", "rest_length": "L0"},
        ],
        "initial": {"x1": -0.5, "x2": 1.2, "x3": 2.9},
    }

    def build() -> Reference:
        x1, x2, x3 = dynamicsymbols("x1 x2 x3")
        m1, m2, m3, k, k2, L0, W = symbols("m1 m2 m3 k k2 L0 W")
        V = sum(
            kk * (sp.sqrt(d**2) - L0) ** 2 / 2
            for kk, d in ((k, x1), (k2, x2 - x1), (k2, x3 - x2), (k, W - x3))
        )
        T = kinetic(m1, x1) + kinetic(m2, x2) + kinetic(m3, x3)
        return lagranges_reference(
            T - V, [x1, x2, x3], [m1, m2, m3, k, k2, L0, W], ReferenceFrame("N")
        )

    run = {"initial": {"x1": -0.5, "x2": 1.2, "x3": 2.9}, "t_end": 0.5, "fps": 40}
    ranges = [both_sides(0.2, 2.0), [(-1.0, 3.0)], [(0.0, 5.0)]]
    return System(
        "spring_chain_between_walls",
        spec,
        build,
        ranges,
        run,
        known=known,
        spring_sides=lambda q, p: [q[0], q[1] - q[0], q[2] - q[1], p["W"] - q[2]],
    )


def two_masses_line(damped: bool, known: dict) -> System:
    spec = {
        "title": "Two masses on a line joined by a spring" + (" and a dashpot" if damped else ""),
        "coordinates": ["x1", "x2"],
        "parameters": {"m1": 1.0, "m2": 2.0, "k": 6.0, "L0": 1.0, "c": 0.7},
        "bodies": [
            {"name": "left", "mass": "m1", "position": ["x1", 0, 0]},
            {"name": "right", "mass": "m2", "position": ["x2", 0, 0]},
        ],
        "springs": [{"a": "left", "b": "right", "k": "k", "rest_length": "L0"}],
        "dampers": [{"a": "left", "b": "right", "c": "c"}] if damped else [],
        "initial": {"x1": 0.0, "x2": 1.4},
    }

    def build() -> Reference:
        x1, x2 = dynamicsymbols("x1 x2")
        m1, m2, k, L0, c = symbols("m1 m2 k L0 c")
        N = ReferenceFrame("N")
        V = k * (sp.sqrt((x2 - x1) ** 2) - L0) ** 2 / 2
        loads = []
        if damped:  # along the line ê = ±N.x: ((v_b − v_a)·ê)ê = (ẋ2 − ẋ1) N.x on either side
            F = -c * (x2.diff(t) - x1.diff(t)) * N.x
            loads = [(moving_point("R", N, x2 * N.x), F), (moving_point("L", N, x1 * N.x), -F)]
        T = kinetic(m1, x1) + kinetic(m2, x2)
        return lagranges_reference(T - V, [x1, x2], [m1, m2, k, L0, c], N, loads)

    run = {"initial": {"x1": 0.0, "x2": 1.4, "x1_dot": 0.3}, "t_end": 3.0, "fps": 20}
    id_ = "dashpot_two_masses_line" if damped else "two_masses_spring_line"
    return System(
        id_,
        spec,
        build,
        [[(-2.0, 2.0)], [(-2.0, 2.0)]],
        run,
        known=known,
        spring_sides=lambda q, p: [q[1] - q[0]],
    )


def two_masses_plane(damped: bool, known: dict | None = None) -> System:
    spec = {
        "title": "Two masses in the plane joined by a spring"
        + (" and a dashpot" if damped else ""),
        "coordinates": ["x1", "y1", "x2", "y2"],
        "parameters": {"m1": 1.0, "m2": 1.5, "k": 9.0, "L0": 1.0, "c": 0.8},
        "bodies": [
            {"name": "p1", "mass": "m1", "position": ["x1", "y1", 0]},
            {"name": "p2", "mass": "m2", "position": ["x2", "y2", 0]},
        ],
        "springs": [{"a": "p1", "b": "p2", "k": "k", "rest_length": "L0"}],
        "dampers": [{"a": "p1", "b": "p2", "c": "c"}] if damped else [],
    }

    def build() -> Reference:
        x1, y1, x2, y2 = dynamicsymbols("x1 y1 x2 y2")
        m1, m2, k, L0, c = symbols("m1 m2 k L0 c")
        N = ReferenceFrame("N")
        r1, r2 = x1 * N.x + y1 * N.y, x2 * N.x + y2 * N.y
        d = r2 - r1
        length = sp.sqrt((x2 - x1) ** 2 + (y2 - y1) ** 2)
        V = k * (length - L0) ** 2 / 2
        loads = []
        if damped:
            e = d / length
            F = -c * (r2.dt(N) - r1.dt(N)).dot(e) * e
            loads = [(moving_point("P2", N, r2), F), (moving_point("P1", N, r1), -F)]
        T = kinetic(m1, x1, y1) + kinetic(m2, x2, y2)
        return lagranges_reference(T - V, [x1, y1, x2, y2], [m1, m2, k, L0, c], N, loads)

    run = {
        "initial": {"x1": 0.0, "y1": 0.0, "x2": 1.2, "y2": 0.5, "x1_dot": 0.5, "y2_dot": -0.8},
        "t_end": 3.0,
        "fps": 20,
    }
    id_ = "dashpot_two_masses_plane" if damped else "two_masses_spring_plane"
    return System(id_, spec, build, [ANY] * 4, run, known=known or {})


# --- velocity-dependent forces --------------------------------------------------------------


def drag_projectile() -> System:
    spec = {
        "title": "Projectile with linear drag",
        "coordinates": ["x", "y"],
        "parameters": {"m": 0.5, "c": 0.3, "g": G},
        "bodies": [{"name": "ball", "mass": "m", "position": ["x", "y", 0]}],
        "gravity": gravity_down(),
        "forces": [{"name": "drag", "on": "ball", "vector": ["-c*x_dot", "-c*y_dot", 0]}],
    }

    def build() -> Reference:
        x, y = dynamicsymbols("x y")
        m, c, g = symbols("m c g")
        N = ReferenceFrame("N")
        r = x * N.x + y * N.y
        loads = [(moving_point("ball", N, r), -c * r.dt(N))]
        return lagranges_reference(kinetic(m, x, y) - m * g * y, [x, y], [m, c, g], N, loads)

    run = {"initial": {"x_dot": 4.0, "y_dot": 6.0}, "t_end": 3.0, "fps": 20}
    return System("drag_projectile", spec, build, [ANY, ANY], run)


def lorentz(id_: str, charge: float) -> System:
    spec = {
        "title": "Charge in a uniform magnetic field",
        "coordinates": ["x", "y"],
        "parameters": {"m": 0.5, "qe": charge, "B": 1.5},
        "bodies": [{"name": "charge", "mass": "m", "position": ["x", "y", 0]}],
        "forces": [{"name": "lorentz", "on": "charge", "vector": ["qe*B*y_dot", "-qe*B*x_dot", 0]}],
    }

    def build() -> Reference:
        x, y = dynamicsymbols("x y")
        m, qe, B = symbols("m qe B")
        N = ReferenceFrame("N")
        r = x * N.x + y * N.y
        loads = [(moving_point("charge", N, r), qe * r.dt(N).cross(B * N.z))]  # q v × B
        return lagranges_reference(kinetic(m, x, y), [x, y], [m, qe, B], N, loads)

    run = {"initial": {"x": 0.2, "y": -0.1, "x_dot": 1.0, "y_dot": 0.5}, "t_end": 6.0, "fps": 20}
    return System(id_, spec, build, [ANY, ANY], run)


# --- rolling, sliding and rope constraints ---------------------------------------------------


def disk_in_cylinder() -> System:
    spec = {
        "title": "Disk rolling inside a cylinder",
        "coordinates": ["theta"],
        "parameters": {"m": 1.0, "r": 0.2, "R": 1.0, "g": G},
        "frames": [{"name": "D", "parent": "N", "axis": "z", "angle": "-(R - r)*theta/r"}],
        "bodies": [
            {
                "name": "disk",
                "kind": "rigid_body",
                "mass": "m",
                "frame": "D",
                "position": ["(R - r)*sin(theta)", "-(R - r)*cos(theta)", 0],
                "inertia": {"ixx": "m*r**2/4", "iyy": "m*r**2/4", "izz": "m*r**2/2"},
            }
        ],
        "gravity": gravity_down(),
    }

    def build() -> Reference:
        (theta,) = dynamicsymbols("theta", seq=True)
        m, r, R, g = symbols("m r R g")
        T = sp.Rational(3, 4) * m * (R - r) ** 2 * theta.diff(t) ** 2  # ½mv² + ½(½mr²)ω²
        V = -m * g * (R - r) * sp.cos(theta)
        return lagranges_reference(T - V, [theta], [m, r, R, g], ReferenceFrame("N"))

    run = {"initial": {"theta": 1.2}, "t_end": 4.0, "fps": 25}
    return System("disk_rolling_in_cylinder", spec, build, [[(-3.0, 3.0)]], run)


def wedge() -> System:
    spec = {
        "title": "Block on a free wedge",
        "coordinates": ["X", "s"],
        "parameters": {"M": 3.0, "m": 1.0, "alpha": 0.6, "g": G, "Lw": 2.0},
        "bodies": [
            {"name": "wedge", "mass": "M", "position": ["X", 0, 0]},
            {
                "name": "block",
                "mass": "m",
                "position": {
                    "frame": "N",
                    "components": ["s*cos(alpha)", "-s*sin(alpha)", 0],
                    "from": "wedge",
                },
            },
        ],
        "gravity": gravity_down(),
    }

    def build() -> Reference:
        X, s = dynamicsymbols("X s")
        M, m, alpha, g, Lw = symbols("M m alpha g Lw")
        bx, by = X + s * sp.cos(alpha), -s * sp.sin(alpha)
        L = kinetic(M, X) + kinetic(m, bx, by) - m * g * by
        return lagranges_reference(L, [X, s], [M, m, alpha, g, Lw], ReferenceFrame("N"))

    run = {"initial": {"s": 0.1, "X_dot": 0.2}, "t_end": 1.0, "fps": 20}
    return System("block_on_moving_wedge", spec, build, [ANY, ANY], run)


def double_atwood() -> System:
    """m1 on one side of a fixed pulley; on the other a massless pulley carrying m2 and m3.
    x: m1 descends (the movable pulley rises by x); y: m2 descends relative to that pulley."""
    spec = {
        "title": "Double Atwood machine",
        "coordinates": ["x", "y"],
        "parameters": {
            "m1": 3.0,
            "m2": 1.0,
            "m3": 1.5,
            "d": 0.4,
            "e": 0.15,
            "L1": 1.0,
            "L2": 1.0,
            "g": G,
        },
        "points": [{"name": "pulley", "position": ["d", "x - L1", 0]}],
        "bodies": [
            {"name": "mass1", "mass": "m1", "position": ["-d", "-x", 0]},
            {"name": "mass2", "mass": "m2", "position": ["d - e", "x - L1 - y", 0]},
            {"name": "mass3", "mass": "m3", "position": ["d + e", "x - L1 - L2 + y", 0]},
        ],
        "gravity": gravity_down(),
    }

    def build() -> Reference:
        x, y = dynamicsymbols("x y")
        m1, m2, m3, d, e, L1, L2, g = symbols("m1 m2 m3 d e L1 L2 g")
        heights = [(m1, -x), (m2, x - L1 - y), (m3, x - L1 - L2 + y)]
        L = sum(kinetic(mi, hi) - mi * g * hi for mi, hi in heights)
        return lagranges_reference(L, [x, y], [m1, m2, m3, d, e, L1, L2, g], ReferenceFrame("N"))

    run = {"initial": {"x_dot": 0.1}, "t_end": 1.0, "fps": 20}
    return System("double_atwood", spec, build, [ANY, ANY], run)


# --- pendulums and orbits --------------------------------------------------------------------


def elastic_polar(known: dict) -> System:
    """No `initial` and r not declared positive: the spring runs O -> bob, |d| = |r|."""
    spec = {
        "title": "Elastic pendulum, no initial state",
        "coordinates": ["r", "theta"],
        "parameters": {"m": 1.0, "k": 30.0, "l0": 1.0, "g": G},
        "bodies": [{"name": "bob", "mass": "m", "position": ["r*sin(theta)", "-r*cos(theta)", 0]}],
        "springs": [{"a": "O", "b": "bob", "k": "k", "rest_length": "l0"}],
        "gravity": gravity_down(),
    }

    def build() -> Reference:
        r, theta = dynamicsymbols("r theta")
        m, k, l0, g = symbols("m k l0 g")
        x, y = r * sp.sin(theta), -r * sp.cos(theta)
        V = k * (sp.sqrt(r**2) - l0) ** 2 / 2 + m * g * y
        return lagranges_reference(
            kinetic(m, x, y) - V, [r, theta], [m, k, l0, g], ReferenceFrame("N")
        )

    run = {"initial": {"r": 1.25, "theta": 0.5}, "t_end": 4.0, "fps": 20}
    return System(
        "elastic_pendulum_no_initial",
        spec,
        build,
        [both_sides(0.3, 2.0), ANY],
        run,
        known=known,
        spring_sides=lambda q, p: [q[0]],
    )


def elastic_cartesian() -> System:
    spec = {
        "title": "Elastic pendulum in x, y",
        "coordinates": ["x", "y"],
        "parameters": {"m": 1.0, "k": 30.0, "l0": 1.0, "g": G},
        "bodies": [{"name": "bob", "mass": "m", "position": ["x", "y", 0]}],
        "springs": [{"a": "O", "b": "bob", "k": "k", "rest_length": "l0"}],
        "gravity": gravity_down(),
    }

    def build() -> Reference:
        x, y = dynamicsymbols("x y")
        m, k, l0, g = symbols("m k l0 g")
        V = k * (sp.sqrt(x**2 + y**2) - l0) ** 2 / 2 + m * g * y
        return lagranges_reference(kinetic(m, x, y) - V, [x, y], [m, k, l0, g], ReferenceFrame("N"))

    run = {"initial": {"x": 0.6, "y": -1.0}, "t_end": 4.0, "fps": 20}
    return System("elastic_pendulum_cartesian", spec, build, [BOTH, BOTH], run)


def spherical_z_up() -> System:
    spec = {
        "title": "Spherical pendulum, z up",
        "coordinates": ["theta", "phi"],
        "parameters": {"m": 1.0, "l": 0.8, "g": G},
        "frames": [
            {"name": "A", "parent": "N", "axis": "z", "angle": "phi"},
            {"name": "B", "parent": "A", "axis": "y", "angle": "theta"},
        ],
        "bodies": [
            {"name": "bob", "mass": "m", "position": {"frame": "B", "components": [0, 0, "-l"]}}
        ],
        "gravity": gravity_down("z"),
    }

    def build() -> Reference:
        theta, phi = dynamicsymbols("theta phi")
        m, rod, g = symbols("m l g")
        T = m * rod**2 / 2 * (theta.diff(t) ** 2 + sp.sin(theta) ** 2 * phi.diff(t) ** 2)
        return lagranges_reference(
            T + m * g * rod * sp.cos(theta), [theta, phi], [m, rod, g], ReferenceFrame("N")
        )

    run = {"initial": {"theta": 0.9, "phi_dot": 2.0}, "t_end": 4.0, "fps": 20}
    return System("spherical_pendulum_z_up", spec, build, [[(0.3, 2.8)], ANY], run)


def kepler() -> System:
    spec = {
        "title": "Kepler orbit in x, y, z",
        "coordinates": ["x", "y", "z"],
        "parameters": {"m": 2.0, "mu": 1.0},
        "bodies": [{"name": "planet", "mass": "m", "position": ["x", "y", "z"]}],
        "potentials": [{"name": "sun", "expression": "-mu*m/sqrt(x**2 + y**2 + z**2)"}],
    }

    def build() -> Reference:
        x, y, z = dynamicsymbols("x y z")
        m, mu = symbols("m mu")
        L = kinetic(m, x, y, z) + mu * m / sp.sqrt(x**2 + y**2 + z**2)
        return lagranges_reference(L, [x, y, z], [m, mu], ReferenceFrame("N"))

    run = {"initial": {"x": 1.0, "y_dot": 1.2, "z_dot": 0.3}, "t_end": 8.0, "fps": 20}
    return System("kepler_3d", spec, build, [BOTH] * 3, run)


# --- the set ---------------------------------------------------------------------------------

ITEM1 = "issue 11 item 1: spring length sign (V = ½k(|d| − ℓ0)² on both sides of the anchor)"


def catalog() -> list[System]:
    return [
        chain(
            "triple_pendulum",
            3,
            True,
            {"initial": {"a1": 0.5, "a2": -0.3, "a3": 0.8}, "t_end": 3.0, "fps": 20},
        ),
        chain(
            "chain_4_links", 4, False, {"initial": {"a1": 0.4, "a3": -0.4}, "t_end": 2.0, "fps": 20}
        ),
        chain(
            "chain_6_links",
            6,
            False,
            {"initial": {"a1": 0.3, "a6": 0.5}, "t_end": 1.5, "fps": 20},
            slow=True,
        ),
        heavy_top(),
        free_body(),
        turntable_particle("turntable_isotropic", 1.5, 4.0, 4.0, 0.0),
        turntable_particle("turntable_negative_omega", -1.5, 4.0, 4.0, 0.0),
        turntable_particle("turntable_gyro_stabilized", 3.5, 2.0, 4.5, 1.0),
        turntable_particle("turntable_springs_rest_length", 1.2, 4.0, 3.0, 0.5),
        rod_on_turntable(),
        bead_on_parabola(),
        driven_pendulum(
            "pendulum_horizontally_driven_pivot",
            False,
            {"m": 1.0, "l": 1.0, "g": G, "a": 0.2, "w": 3.0},
            {"initial": {"theta": 0.3}, "t_end": 5.0, "fps": 20},
        ),
        driven_pendulum(
            "kapitza_pendulum",
            True,
            {"m": 1.0, "l": 1.0, "g": G, "a": 0.05, "w": 100.0},
            {"initial": {"theta": math.pi - 0.1}, "t_end": 2.0, "fps": 50},
        ),
        spring_anchor_line({}),
        spring_chain_walls({}),
        two_masses_line(False, {}),
        two_masses_plane(False),
        two_masses_line(True, {}),
        two_masses_plane(True),
        drag_projectile(),
        lorentz("lorentz_positive_charge", 2.0),
        lorentz("lorentz_negative_charge", -2.0),
        disk_in_cylinder(),
        wedge(),
        double_atwood(),
        elastic_polar({}),
        elastic_cartesian(),
        spherical_z_up(),
        kepler(),
    ]


SYSTEMS = {s.id: s for s in catalog()}
