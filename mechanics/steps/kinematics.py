"""Step 3 (notes I.B, eq. 9, 15–16): positions and velocities of every body.

A position written along a turning frame B's unit vectors is differentiated by the transport
theorem, v = (dr/dt)_B + ω_B/N × r (the notes' eq. 9 with their F our N): the relative rate is
the one seen in B, the frame that turns; the step shows both terms, named by B as the model names
it, so no F appears beside N; sympy.physics.vector does the
same algebra, so the printed pieces and the velocity used for T agree by construction.
"""

from __future__ import annotations

from sympy.physics.vector import Vector

from mechanics.model import Model
from mechanics.steps import Line, Step, Work, sub, vec_line


def kinematics(model: Model, work: Work) -> Step:
    lines: list[Line] = []
    transport = []
    turning: list[str] = []  # the frames that turn, in the order their bodies come
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
            if natural not in turning:
                turning.append(natural)
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
        theorem = ", ".join(
            rf"$\vec v = (d\vec r/dt)_{{{sub(B)}}} + \vec\omega_{{{sub(B)}/N}} \times \vec r$"
            + (f" for a body in {B}" if len(turning) > 1 else "")
            for B in turning
        )
        where = " and ".join(turning)
        text += (
            f" Frame{'s' if len(turning) > 1 else ''} {where} turn{'' if len(turning) > 1 else 's'}"
            f": the transport theorem {theorem} (eq. 9, the notes' F being N) gives the velocity, "
            r"the rate of $\vec r$ seen in the turning frame plus that frame's turning."
        )
    data = {"transport": transport, "transport_frames": turning}
    return Step("kinematics", "Kinematics", text, lines, data)
