"""Posted systems past the built-in catalog that a class sends together (issue 23, item 8): the
restricted three-body problem in a rotating frame, written two ways, and PyDy's conical pendulum
of two and three rigid links with bobs. The derive benchmark (``python -m benchmarks derive
three_body ...``) times them cold; tests/derivation/test_derive_speed_systems.py checks their
equations against sympy's LagrangesMethod built from first principles.
"""

from __future__ import annotations

#: The restricted three-body problem in units where G(M₁ + M₂) = 1, the primaries 1 apart and
#: the frame turning at Ω = 1: the primaries rest at x = −μ and x = 1 − μ on the frame's x axis.
THREE_BODY = {
    "title": "Restricted three-body problem (rotating frame)",
    "coordinates": ["x", "y"],
    "parameters": {"m": 1.0, "mu": 0.01215, "Omega": 1.0},
    "initial": {"x": 0.5, "y": 0.8, "x_dot": 0.0, "y_dot": 0.0},
    "frames": [{"name": "H", "parent": "N", "axis": "z", "angle": "Omega*t"}],
    "bodies": [{"name": "p", "mass": "m", "position": {"frame": "H", "components": ["x", "y", 0]}}],
    "potentials": [
        {
            "name": "gravity_of_primaries",
            "expression": "-m*(1-mu)/sqrt((x+mu)**2+y**2) - m*mu/sqrt((x-1+mu)**2+y**2)",
        }
    ],
}

#: The same problem with G, both primaries' masses and their distance R as parameters: the
#: frame turns at Ω = √(G (M₁ + M₂)/R³), the primaries sit at their centre of mass's distances.
THREE_BODY_SI = {
    "title": "Restricted three-body problem (rotating frame, G, M1, M2, R)",
    "coordinates": ["x", "y"],
    "parameters": {"m": 1.0, "G": 1.0, "M1": 0.98785, "M2": 0.01215, "R": 1.0},
    "initial": {"x": 0.5, "y": 0.8, "x_dot": 0.0, "y_dot": 0.0},
    "frames": [{"name": "H", "parent": "N", "axis": "z", "angle": "sqrt(G*(M1+M2)/R**3)*t"}],
    "bodies": [{"name": "p", "mass": "m", "position": {"frame": "H", "components": ["x", "y", 0]}}],
    "potentials": [
        {
            "name": "gravity_of_primaries",
            "expression": "-G*M1*m/sqrt((x+M2*R/(M1+M2))**2+y**2)"
            " - G*M2*m/sqrt((x-M1*R/(M1+M2))**2+y**2)",
        }
    ],
}


def conical_pendulum(n: int) -> dict:
    """PyDy's n-link conical pendulum: link i's frame is turned from link i−1's (the ground's for
    the first) by β_i about x, then by α_i about the new z; each link is a rigid body of mass M_i
    and central inertia (Ixx_i, Iyy_i, Izz_i) along its frame's −y, with a bob m_i at its end;
    gravity along −y."""
    frames, bodies = [], []
    parent = "N"
    for i in range(1, n + 1):
        frames.append({"name": f"T{i}", "parent": parent, "axis": "x", "angle": f"beta{i}"})
        frames.append({"name": f"L{i}", "parent": f"T{i}", "axis": "z", "angle": f"alpha{i}"})
        parent = f"L{i}"
        start = {} if i == 1 else {"from": f"bob{i - 1}"}
        bodies.append(
            {
                "name": f"link{i}",
                "kind": "rigid_body",
                "mass": f"M{i}",
                "frame": f"L{i}",
                "position": {"frame": f"L{i}", "components": [0, f"-l{i}/2", 0], **start},
                "inertia": {"ixx": f"Ixx{i}", "iyy": f"Iyy{i}", "izz": f"Izz{i}"},
            }
        )
        bodies.append(
            {
                "name": f"bob{i}",
                "mass": f"m{i}",
                "position": {"frame": f"L{i}", "components": [0, f"-l{i}", 0], **start},
            }
        )
    parameters = {"g": 9.81} | {f"{p}{i}": 1.0 for i in range(1, n + 1) for p in ("M", "m", "l")}
    parameters |= {f"{p}{i}": 0.1 for i in range(1, n + 1) for p in ("Ixx", "Izz")}
    parameters |= {f"Iyy{i}": 0.01 for i in range(1, n + 1)}
    return {
        "title": f"{n}-link conical pendulum",
        "coordinates": [f"alpha{i}" for i in range(1, n + 1)]
        + [f"beta{i}" for i in range(1, n + 1)],
        "parameters": parameters,
        "frames": frames,
        "bodies": bodies,
        "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    }


#: By the names the benchmark knows them.
LARGE_SYSTEMS = {
    "three_body": THREE_BODY,
    "three_body_si": THREE_BODY_SI,
    "conical_pendulum_2": conical_pendulum(2),
    "conical_pendulum_3": conical_pendulum(3),
}
