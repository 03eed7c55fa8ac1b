"""A run as a standalone Python script: the scene's equations, parameters, initial state, method,
tolerances and sample times, integrated with numpy and scipy only.

Why a script: a student (or a referee) can check a run without this app, read the equations as
code, and change them. The script integrates the very state the app integrates, y = [q, q̇, W_NC
(, W_t)], with the same right-hand side printed from the same sympy expressions, so an adaptive
method takes the same steps and the trajectories agree to rounding, far inside the tolerance.

Nothing the user typed reaches the printed code but numbers: every symbol becomes a numbered
slot (``y_0`` for q₀, ``p_3`` for the fourth parameter, ``x_12`` for a common subexpression),
and the printed expressions are parsed back (`ast`) and refused unless they consist of arithmetic
on those names, numbers and ``math`` functions (the whitelist, as mechanics/native does for C).
Names and titles appear only as Python string literals written by ``repr``.
"""

from __future__ import annotations

import ast
import inspect
import json
from typing import Any

import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from mechanics.integrators import METHODS
from mechanics.spec import SpecError

#: ``math`` functions the printed expressions may call.
MATH_FUNCTIONS = frozenset(
    {"sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh"}
    | {"acosh", "atanh", "exp", "log", "log10", "log2", "sqrt", "copysign", "fabs", "floor"}
    | {"ceil", "pi", "e", "inf", "nan", "hypot", "pow", "erf"}
)
_BUILTINS = frozenset({"abs", "min", "max", "float"})
_NODES = (
    ast.Expression, ast.BinOp, ast.UnaryOp, ast.Call, ast.Name, ast.Load, ast.Constant,
    ast.Attribute, ast.IfExp, ast.Compare, ast.BoolOp, ast.operator, ast.unaryop, ast.cmpop,
    ast.boolop,
)  # fmt: skip
#: scipy's method for each of the app's adaptive ones (the C and Fortran DOP853 are DOP853).
SCIPY_METHOD = {"dop853_c": "DOP853", "dop853_fortran": "DOP853"}


class ScriptError(ValueError):
    """An expression that does not print as whitelisted Python (never seen on the built-in
    scenes; a guard, like mechanics/native's)."""


def _slot_name(node: ast.AST) -> bool:
    name = node.id
    if name in ("t", "math") or name in _BUILTINS:
        return True
    head, _, digits = name.partition("_")
    return head in ("y", "p", "x") and digits.isdigit()


def checked_expression(code: str) -> str:
    """``code`` if it is arithmetic on slots, numbers and math functions; else ScriptError."""
    try:
        tree = ast.parse(code, mode="eval")
    except SyntaxError as exc:
        raise ScriptError(f"unprintable expression: {exc.msg}") from None
    for node in ast.walk(tree):
        if not isinstance(node, _NODES):
            raise ScriptError(f"the expression holds a {type(node).__name__}")
        if isinstance(node, ast.Name) and not _slot_name(node):
            raise ScriptError(f"the expression names '{node.id}'")
        if isinstance(node, ast.Attribute) and not (
            isinstance(node.value, ast.Name)
            and node.value.id == "math"
            and node.attr in MATH_FUNCTIONS
        ):
            raise ScriptError(f"the expression uses '.{node.attr}'")
        if isinstance(node, ast.Constant) and not isinstance(node.value, int | float):
            raise ScriptError("the expression holds a constant that is not a number")
    return code


def _printer() -> PythonCodePrinter:
    return PythonCodePrinter({"fully_qualified_modules": True, "standard": "python3"})


def equations_source(inputs: dict[str, Any]) -> str:
    """The body of ``derivatives(t, y, p)`` from a compiled scene's ``native_inputs`` (the same
    expressions the C right-hand side is printed from)."""
    args, n = inputs["args"], inputs["n"]
    slots = {args[0]: sp.Symbol("t")}
    slots |= {a: sp.Symbol(f"y_{i}") for i, a in enumerate(args[1 : 2 * n + 1])}
    slots |= {a: sp.Symbol(f"p_{k}") for k, a in enumerate(args[2 * n + 1 :])}
    solved = "accelerations" in inputs
    outputs = inputs["accelerations"] if solved else [*inputs["mass"], *inputs["forcing"]]
    rates = list(inputs["power"])
    exprs = [_sympy(e).xreplace(slots) for e in [*outputs, *rates]]
    stray = set().union(*(e.free_symbols for e in exprs)) - set(slots.values())
    if stray:
        raise ScriptError(f"unexpected symbols {sorted(map(str, stray))}")
    temps, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("x_"))
    printer = _printer()

    def code(e: sp.Basic) -> str:
        return checked_expression(printer.doprint(e))

    n_params = len(args) - 2 * n - 1
    lines = []
    if 2 * n:
        lines.append(f"    {', '.join(f'y_{i}' for i in range(2 * n))}, *_ = y")
    if n_params:
        lines.append(f"    {', '.join(f'p_{k}' for k in range(n_params))}, = p")
    lines += [f"    {s} = {code(e)}" for s, e in temps]
    rate_code = ", ".join(code(e) for e in reduced[len(reduced) - len(rates) :])
    if solved:
        accel = ", ".join(code(e) for e in reduced[:n])
        lines.append(f"    q_ddot = [{accel}]")
    else:
        mass = ", ".join(code(e) for e in reduced[: n * n])
        forcing = ", ".join(code(e) for e in reduced[n * n : n * n + n])
        lines.append(f"    mass = np.array([{mass}], dtype=float).reshape({n}, {n})")
        lines.append(f"    forcing = np.array([{forcing}], dtype=float)")
        lines.append("    q_ddot = np.linalg.solve(mass, forcing).tolist()  # M q'' = f")
    lines.append(f"    return [{', '.join(f'y_{n + i}' for i in range(n))}, *q_ddot, {rate_code}]")
    return "\n".join(lines)


def _sympy(e: Any) -> sp.Basic:
    if isinstance(e, sp.Basic):
        return e
    return sp.Integer(e) if isinstance(e, int) else sp.Float(float(e))


def script_source(
    compiled: Any,
    options: Any,
    values: list[float],
    y0: list[float],
    title: str,
    origin: str,
) -> str:
    """The whole script for one run of ``compiled`` (a mechanics.numeric.CompiledScene) with the
    request ``options`` (a SimulationRequest), its parameter values and initial state (as
    mechanics.simulate.check_request returned them)."""
    n = compiled.n
    method = options.method
    fixed = METHODS[method].kind == "fixed"
    spec = compiled.derivation.model.spec
    stops = [f"{s.name}: {s.message}" for s in spec.stops] if spec.stops else []
    constants = [
        f"TITLE = {title!r}",
        f"SOURCE = {origin!r}",
        f"COORDINATES = {list(compiled.coordinates)!r}",
        f"PARAMETERS = {dict(zip(compiled.parameters, map(float, values), strict=True))!r}",
        f"INITIAL = {dict(_initial_names(compiled.coordinates, y0))!r}",
        f"EXTRA_STATES = {compiled.extras!r}  # W_nc (and W_t): the work riding along with q, q'",
        f"METHOD = {method!r}  # the app's name",
        f"SCIPY_METHOD = {SCIPY_METHOD.get(method, method)!r}",
        f"RTOL = {float(options.rtol)!r}",
        f"ATOL = {float(options.atol)!r}",
        f"DT = {None if options.dt is None else float(options.dt)!r}",
        f"T_END = {float(options.t_end)!r}",
        f"FPS = {float(options.fps)!r}",
        *_fixed_grid_constants(options, fixed),
        f"STOPS_NOT_MODELLED = {stops!r}",
    ]
    return _TEMPLATE.format(
        constants="\n".join(constants),
        equations=equations_source(compiled.native_inputs),
        n=n,
        integrator=fixed_step_source(method) if fixed else _ADAPTIVE,
    )


def _initial_names(coordinates: list[str], y0: list[float]) -> list[tuple[str, float]]:
    n = len(coordinates)
    names = [*coordinates, *(f"{q}_dot" for q in coordinates)]
    return [(name, float(v)) for name, v in zip(names, y0[: 2 * n], strict=True)]


def compiled_for(scene_id: str | None, key: str | None, options: Any) -> tuple[Any, list, Any]:
    """The compiled scene a run with ``options`` integrates (the variant for the side of its
    anchors each spring starts on, as mechanics.simulate picks it), its parameter values and
    y0; SpecError naming the field for a request the run would refuse."""
    from mechanics.numeric import compiled_scene, compiled_spec
    from mechanics.simulate import MAX_BRANCH_FLIPS, _OtherBranch, check_request

    branches: dict[int, int] = {}
    for _ in range(MAX_BRANCH_FLIPS):
        variant = tuple(sorted(branches.items()))
        if scene_id is not None:
            c = compiled_scene(scene_id, variant)
        else:
            c = compiled_spec(json.loads(key), variant)
        try:
            values, y0 = check_request(c, options)
            return c, values, y0
        except _OtherBranch as other:
            branches = {**c.derivation.model.branches, **other.flips}
    raise SpecError([{"field": "initial", "message": "no derivation matches this state"}])


def run_script(scene_id: str | None, key: str | None, options: Any, origin: str) -> str:
    """The script of a run (a pool job for posted specs: it compiles the scene with sympy)."""
    c, values, y0 = compiled_for(scene_id, key, options)
    title = c.derivation.model.spec.title or "Your system"
    try:
        return script_source(c, options, values, list(y0), title, origin)
    except ScriptError as exc:
        raise SpecError(
            [{"field": "scene", "message": f"cannot write it as Python: {exc}"}]
        ) from None


def fixed_step_source(method: str) -> str:
    """The app's own stepper for a fixed-step method (mechanics/integrators.py), copied into the
    script by its source, with the helpers it calls: the script steps with the very arithmetic
    the app steps with, and there is one implementation to maintain."""
    from mechanics import integrators

    stepper = integrators._STEPPERS[method]
    parts = [inspect.getsource(stepper)]
    if method == "implicit_midpoint":  # it checks finiteness and may give up
        parts += [inspect.getsource(integrators._finite), inspect.getsource(integrators._Stop)]
    return "\n\n".join(parts) + _FIXED_LOOP.replace("STEPPER", stepper.__name__)


def _fixed_grid_constants(options: Any, fixed: bool) -> list[str]:
    """The sample grid of a fixed-step run as /simulate builds it (whole steps of dt apart)."""
    if not fixed:
        return ["SAMPLE_STEPS = None  # adaptive: samples 1/FPS apart", "SAMPLE_COUNT = None"]
    from mechanics.simulate import fixed_step_grid

    times, stride = fixed_step_grid(options.t_end, options.fps, options.dt)
    return [
        f"SAMPLE_STEPS = {stride!r}  # steps of DT between two samples (about 1/FPS)",
        f"SAMPLE_COUNT = {len(times)!r}",
    ]


_FIXED_LOOP = '''

def integrate(y0, times):
    """Fixed steps landing on every sample: each interval gets ceil(dt_out / DT) equal steps."""
    out, y = [y0], y0
    for t0, t1 in zip(times[:-1], times[1:]):
        m = max(1, math.ceil((t1 - t0) / DT - 1e-9))
        h = (t1 - t0) / m
        for i in range(m):
            y = STEPPER(derivatives, t0 + i * h, y, h, N)
        out.append(y)
    return np.array(out)
'''

_ADAPTIVE = '''
def integrate(y0, times):
    """scipy's adaptive stepper, sampled at the output times by its dense output."""
    if len(times) == 1:
        return np.array([y0])
    sol = solve_ivp(
        derivatives, (times[0], times[-1]), y0, method=SCIPY_METHOD, t_eval=times,
        rtol=RTOL, atol=ATOL,
    )
    if sol.status != 0:
        print(f"the solver stopped early: {sol.message}", file=sys.stderr)
    return sol.y.T
'''

_TEMPLATE = '''#!/usr/bin/env python3
"""A run of a Lagrange Lab scene, reproduced with numpy and scipy only (the scene is TITLE below).

The equations of motion are the scene's q'' = M(q)^-1 f(q, q', t) as Lagrange's equations give
them, written with numbered names: y_0.. is the state (q, then q', then the work W_nc of the
non-conservative forces), p_0.. the parameters in the order of PARAMETERS, x_0.. common
subexpressions.

    python run.py               # prints the final state
    python run.py --json out.json
    python run.py --csv out.csv
"""

import argparse
import json
import math
import sys

import numpy as np
from scipy.integrate import solve_ivp

{constants}

N = {n}
P = list(PARAMETERS.values())


def equations(t, y, p):
    """dy/dt as a list: q', q'' and the rate of each extra state."""
{equations}


def derivatives(t, y):
    return np.array(equations(t, y, P), dtype=float)

{integrator}

def sample_times():
    """The app's output samples: t_end * fps + 1 of them (the last at or before T_END); for a
    fixed step, SAMPLE_COUNT samples every SAMPLE_STEPS steps of exactly DT."""
    if SAMPLE_STEPS is not None:
        return np.arange(SAMPLE_COUNT) * (SAMPLE_STEPS * DT)
    count = int(math.floor(T_END * FPS + 1e-9)) + 1
    return np.linspace(0.0, (count - 1) / FPS, count)


def main():
    # argparse %-formats a description that contains "%(prog)": the title's own % are doubled
    # and "%(prog).0s" (the program's name, zero characters of it) makes that always happen,
    # so the help prints the title as written, whatever % it holds.
    description = "Integrate " + TITLE.replace("%", "%%") + "%(prog).0s"
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--json", help="write t, q and q_dot as JSON to this file")
    parser.add_argument("--csv", help="write t, q and q_dot as CSV to this file")
    args = parser.parse_args()
    for stop in STOPS_NOT_MODELLED:
        print("note: the app ends a run where this holds; this script does not:", stop,
              file=sys.stderr)
    names = list(INITIAL)
    y0 = np.array([INITIAL[k] for k in names] + [0.0] * EXTRA_STATES)
    times = sample_times()
    y = integrate(y0, times)
    times = times[: len(y)]
    result = {{
        "t": times.tolist(),
        "q": {{q: y[:, i].tolist() for i, q in enumerate(COORDINATES)}},
        "q_dot": {{q: y[:, N + i].tolist() for i, q in enumerate(COORDINATES)}},
        "W_nc": y[:, 2 * N].tolist(),
    }}
    if args.json:
        with open(args.json, "w") as out:
            json.dump(result, out)
    if args.csv:
        with open(args.csv, "w") as out:
            out.write(",".join(["t", *names, "W_nc"]) + "\\n")
            for i, t in enumerate(times):
                row = [t, *y[i, : 2 * N], y[i, 2 * N]]
                out.write(",".join(repr(float(v)) for v in row) + "\\n")
    if not (args.json or args.csv):
        print("t =", times[-1], dict(zip(names, y[-1, : 2 * N].tolist())))


if __name__ == "__main__":
    main()
'''
