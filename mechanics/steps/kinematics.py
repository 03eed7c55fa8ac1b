"""Step 3 (notes I.B, eq. 9, 15–16): positions and velocities of every body.

A position written along a moving frame's unit vectors is differentiated by the transport
theorem, v = (dr/dt)_F + ω_F/N × r, and the step shows both terms; sympy.physics.vector does the
same algebra, so the printed pieces and the velocity used for T agree by construction.
"""

from __future__ import annotations

from sympy.physics.vector import Vector

from mechanics.model import Model
from mechanics.steps import Line, Step, Work, sub, vec_line


def kinematics(model: Model, work: Work) -> Step:
    lines: list[Line] = []
    transport = []
    for b in model.bodies:
        natural = b.natural_frame
        r = b.position
        lines.append(vec_line(rf"\vec{{r}}_{{{sub(b.name)}}}", r, natural, model, f"r of {b.name}"))
        if natural != "N" and model.frame(natural).ang_vel_in(model.N) != Vector(0):
            frame = model.frame(natural)
            w = frame.ang_vel_in(model.N)
            rel = r.dt(frame)
            lines.append(
                vec_line(
                    r"\left(\frac{d\vec{r}}{dt}\right)_{" + natural + "}",
                    rel,
                    natural,
                    model,
                    f"rate of r of {b.name} seen in {natural}",
                )
            )
            lines.append(
                vec_line(
                    rf"\vec{{\omega}}_{{{natural}/N}} \times \vec{{r}}_{{{sub(b.name)}}}",
                    w.cross(r),
                    natural,
                    model,
                    f"transport term for {b.name}",
                )
            )
            transport.append(b.name)
        lines.append(
            vec_line(
                rf"\vec{{v}}_{{{sub(b.name)}}}",
                model.velocity(b.name),
                natural,
                model,
                f"v of {b.name}",
            )
        )
        if b.frame is not None:
            lines.append(
                vec_line(
                    rf"\vec{{\omega}}_{{{sub(b.name)}}}",
                    b.frame.ang_vel_in(model.N),
                    "N",
                    model,
                    f"angular velocity of {b.name}",
                )
            )
    text = (
        r"Write each body's position $\vec r_i(q, t)$ in the frame where it is natural and "
        "differentiate in N (eq. 16). N is the fixed (inertial) frame, the notes' F, with unit "
        r"vectors $\hat\imath, \hat\jmath, \hat k$; a subscript /N means relative to it."
    )
    if transport:
        text += (
            r" Where the frame turns, the transport theorem "
            r"$\vec v = (d\vec r/dt)_F + \vec\omega \times \vec r$ (eq. 9) "
            "gives the velocity."
        )
    return Step("kinematics", "Kinematics", text, lines, {"transport": transport})
