"""Systems beyond the catalog that several test modules pose (the physics play-tests' specs), in
one place so a fix to one spec is a fix to all: each module still derives its own expectations.
"""

from __future__ import annotations

import copy

#: A frictionless ladder, top on the wall x = 0, foot on the floor y = 0: θ from the wall, G at
#: (L/2 sin θ, L/2 cos θ). The wall can only push: the run stops where its force would pull.
_LADDER = {
    "title": "ladder",
    "coordinates": ["theta"],
    "parameters": {"m": 1.0, "L": 2.0, "g": 9.81},
    "initial": {"theta": 0.3, "theta_dot": 0.0},
    "frames": [{"name": "R", "parent": "N", "axis": "z", "angle": "theta"}],
    "bodies": [
        {
            "name": "ladder",
            "kind": "rigid_body",
            "mass": "m",
            "frame": "R",
            "position": ["L/2*sin(theta)", "L/2*cos(theta)", 0],
            "inertia": {"ixx": "m*L**2/12", "iyy": 0, "izz": "m*L**2/12"},
        }
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
    "stops": [
        {
            "name": "wall_contact",
            "tension": "ladder",
            "along": [1, 0, 0],
            "message": "the top leaves the wall",
        }
    ],
}

#: A uniform cylinder of radius r rolling without slipping inside a fixed one of radius R: its
#: frame turns by −(R − r)θ/r as its centre goes round at angle θ.
_CYLINDER_IN_CYLINDER = {
    "title": "cyl in cyl",
    "coordinates": ["theta"],
    "parameters": {"m": 2.0, "R": 1.0, "r": 0.25, "g": 9.81},
    "initial": {"theta": 0.4, "theta_dot": 0.0},
    "frames": [{"name": "D", "parent": "N", "axis": "z", "angle": "-(R-r)*theta/r"}],
    "bodies": [
        {
            "name": "cyl",
            "kind": "rigid_body",
            "mass": "m",
            "frame": "D",
            "position": ["(R-r)*sin(theta)", "-(R-r)*cos(theta)", 0],
            "inertia": {"ixx": "m*r**2/4", "iyy": "m*r**2/4", "izz": "m*r**2/2"},
        }
    ],
    "gravity": {"acceleration": "g", "direction": [0, -1, 0]},
}

#: A puck on a frictionless turntable turning at Ω, on a spring of rest length 0 to the axis, in
#: Cartesian coordinates of the turning frame (no cyclic coordinate).
_TURNTABLE_CARTESIAN = {
    "title": "rotating cartesian",
    "coordinates": ["x", "y"],
    "parameters": {"m": 1.0, "k": 4.0, "Omega": 2.0},
    "initial": {"x": 0.1, "y": 0.0, "x_dot": 0.2, "y_dot": 0.1},
    "frames": [{"name": "H", "parent": "N", "axis": "z", "angle": "Omega*t"}],
    "points": [{"name": "o", "position": [0, 0, 0]}],
    "bodies": [
        {
            "name": "p",
            "kind": "particle",
            "mass": "m",
            "position": {"frame": "H", "components": ["x", "y", 0]},
        }
    ],
    "springs": [{"name": "s", "a": "o", "b": "p", "k": "k", "rest_length": 0}],
}


#: The same puck in polar coordinates (r, φ) of the turning frame: φ is cyclic, so p_φ is conserved.
_TURNTABLE_POLAR = {
    "title": "turntable polar",
    "coordinates": ["r", "phi"],
    "parameters": {"m": 1.0, "k": 4.0, "Omega": 1.5},
    "initial": {"r": 1.0, "phi": 0.0, "r_dot": 0.3, "phi_dot": 0.5},
    "frames": [
        {"name": "H", "parent": "N", "axis": "z", "angle": "Omega*t"},
        {"name": "P", "parent": "H", "axis": "z", "angle": "phi"},
    ],
    "points": [{"name": "centre", "position": [0, 0, 0]}],
    "bodies": [
        {
            "name": "puck",
            "kind": "particle",
            "mass": "m",
            "position": {"frame": "P", "components": ["r", 0, 0]},
        }
    ],
    "springs": [{"name": "s", "a": "centre", "b": "puck", "k": "k", "rest_length": 0}],
}


def ladder(stops: bool = True) -> dict:
    """A fresh copy: tests change parameters and stops. Without ``stops`` the run goes on past
    where the top would leave the wall (a drawing test pauses at the start)."""
    spec = copy.deepcopy(_LADDER)
    if not stops:
        del spec["stops"]
    return spec


def cylinder_in_cylinder() -> dict:
    return copy.deepcopy(_CYLINDER_IN_CYLINDER)


def turntable_cartesian() -> dict:
    return copy.deepcopy(_TURNTABLE_CARTESIAN)


def turntable_polar(positive: bool = False) -> dict:
    """With ``positive``, r is declared positive (the pole r = 0 is then outside the states)."""
    spec = copy.deepcopy(_TURNTABLE_POLAR)
    if positive:
        spec["positive_coordinates"] = ["r"]
    return spec
