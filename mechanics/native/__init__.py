"""Compiled numerics: the scene's right-hand side as generated C, stepped by a DOP853 loop in C.

Why: a Python right-hand side costs ~2 µs a call and scipy's DOP853 adds ~100 µs of Python per
step, which caps a 20 s double-pendulum run near 0.1 s; the same steps in C cost about a
millisecond. The C is generated from the same sympy expressions as the Python code (with common
subexpressions eliminated), so nothing the user typed reaches the compiler but numbers: every
symbol becomes an array slot (y[i], p[k]) and the printed code is checked against a whitelist of
identifiers before it is compiled.

Compiling needs a C compiler (`cc`, or ``$LAGRANGE_LAB_CC``; set it to ``none`` to switch this
off). Each shared library is cached on disk under a hash of its source, so a scene compiles once
per machine, and loaded only after its bytes and its source match the sha256 recorded beside it
when it was built (a truncated or swapped file is rebuilt, never run). Without a compiler
everything still works: `available()` says why not, and callers fall back to scipy's DOP853,
which takes the same steps.
"""

from __future__ import annotations

import ctypes
import functools
import hashlib
import json
import logging
import os
import platform
import re
import shutil
import subprocess
import tempfile
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import sympy as sp
from scipy.integrate._ivp import dop853_coefficients as tableau
from sympy.printing.c import C99CodePrinter
from sympy.printing.codeprinter import PrintMethodNotImplementedError

from mechanics.cache import cache_dir

log = logging.getLogger(__name__)

ENV_VAR = "LAGRANGE_LAB_CC"
COMPILE_TIMEOUT = 60.0
FLAGS = ("-O2", "-shared", "-fPIC", "-std=c99", "-D_POSIX_C_SOURCE=200809L")

#: Status codes of lab_dop853 (see dop853.c).
OK, STEP_BUDGET, TOO_SMALL, NONFINITE, WALL_TIME, RHS_ERROR, NO_MEMORY = range(7)
#: Codes a generated right-hand side returns.
RHS_SINGULAR = 2

RHS_SIGNATURE = ctypes.CFUNCTYPE(
    ctypes.c_int,
    ctypes.c_double,
    ctypes.POINTER(ctypes.c_double),
    ctypes.POINTER(ctypes.c_double),
    ctypes.POINTER(ctypes.c_double),
)


class NativeUnavailable(RuntimeError):
    """No compiled path here (no compiler, a failed build, an expression C cannot print).

    Its reason reaches clients (a run's ``warnings``): the folders of an absolute path in it (the
    server's cache, a compiler's temporary files) are cut to the file's name (issue 24)."""

    def __init__(self, reason: str) -> None:
        super().__init__(re.sub(r"(?<![\w.~-])/(?:[^/\s'\"]+/)+", "", reason))


class _Result(ctypes.Structure):
    _fields_ = [
        ("nfev", ctypes.c_long),
        ("nsteps", ctypes.c_long),
        ("nrejected", ctypes.c_long),
        ("t", ctypes.c_double),
        ("t_bad", ctypes.c_double),
        ("n_out", ctypes.c_int),
        ("rhs_code", ctypes.c_int),
    ]


def compiler() -> str | None:
    """The C compiler to use, or None: ``$LAGRANGE_LAB_CC`` (``none`` disables), else cc/gcc."""
    configured = os.environ.get(ENV_VAR)
    if configured is not None:
        return None if configured.strip().lower() in ("", "none", "0", "off") else configured
    return shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")


_locks: dict[str, threading.Lock] = {}
_locks_guard = threading.Lock()
#: Sources this compiler refused, by (compiler, library path): a broken compiler is run once
#: per source and process, not again on every request (a different compiler is tried afresh).
_refused: dict[tuple[str, str], NativeUnavailable] = {}


def _build(source: str, kind: str) -> ctypes.CDLL:
    """Compile `source` to a shared library (once per machine: cached by the hash of source,
    flags and platform) and load it. Raises NativeUnavailable with the reason.

    A cached library is loaded only when its sidecar (``<name>.json``) records the sha256 of the
    library's bytes and of the source it was built from and both match: a truncated, damaged or
    swapped file is rebuilt, never run. Nothing of it is taken from another machine: each one
    generates the C itself (7-26 ms for the built-in scenes, too little to share through Redis)."""
    cc = compiler()
    if cc is None:
        raise NativeUnavailable("no C compiler found (install gcc, or set LAGRANGE_LAB_CC)")
    digest = hashlib.sha256(
        "\0".join([source, " ".join(FLAGS), platform.machine(), platform.system()]).encode()
    ).hexdigest()[:24]
    folder = cache_dir() / "native"
    target = folder / f"{kind}-{digest}.so"
    with _locks_guard:
        lock = _locks.setdefault(digest, threading.Lock())
    with lock:
        if (cc, str(target)) in _refused:
            raise _refused[cc, str(target)]
        library = _verified_library(target, source)
        if library is None:
            library = _compile(cc, source, target)
            _prune(folder)
        return _load(library, folder)


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _verified_library(target: Path, source: str) -> bytes | None:
    """The cached library's bytes if its sidecar vouches for them and for `source`, else None."""
    try:
        record = json.loads(target.with_suffix(".json").read_text())
        data = target.read_bytes()
    except FileNotFoundError:
        return None
    except (OSError, ValueError) as exc:
        log.warning("native: cannot read the cached %s (%s); rebuilding", target.name, exc)
        return None
    if not (
        isinstance(record, dict)
        and record.get("source_sha256") == _sha256(source.encode())
        and record.get("library_sha256") == _sha256(data)
    ):
        log.warning("native: %s does not match its record; rebuilding", target.name)
        return None
    return data


def _compile(cc: str, source: str, target: Path) -> bytes:
    """Compile `source` into `target` and its sidecar (each written atomically); its bytes."""
    folder = target.parent
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=folder) as tmp:
            c_file, so_file = Path(tmp) / "src.c", Path(tmp) / "out.so"
            c_file.write_text(source)
            done = subprocess.run(
                [cc, *FLAGS, "-o", str(so_file), str(c_file), "-lm"],
                capture_output=True,
                text=True,
                timeout=COMPILE_TIMEOUT,
            )
            if done.returncode != 0:
                log.warning("C compile failed: %s", done.stderr[-2000:])
                failure = NativeUnavailable(f"the C compiler failed: {done.stderr[-300:]}")
                _refused[cc, str(target)] = failure
                raise failure
            data = so_file.read_bytes()
            record = Path(tmp) / "record.json"
            record.write_text(
                json.dumps(
                    {
                        "library_sha256": _sha256(data),
                        "source_sha256": _sha256(source.encode()),
                        "compiler": cc,
                        "flags": list(FLAGS),
                    }
                )
            )
            # Library first, then its record: a reader between the two sees a mismatch and
            # rebuilds; atomic replaces mean no reader sees half a file.
            os.replace(so_file, target)
            os.replace(record, target.with_suffix(".json"))
    except (OSError, subprocess.SubprocessError) as exc:
        raise NativeUnavailable(f"could not compile C code: {exc}") from exc
    return data


def _load(library: bytes, folder: Path) -> ctypes.CDLL:
    """Load exactly the verified bytes: a private copy, so the file cannot change between the
    check and dlopen (and dlopen never hands back another library loaded under the same name)."""
    try:
        fd, path = tempfile.mkstemp(dir=folder, prefix=".load-", suffix=".so")
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(library)
            return ctypes.CDLL(path)
        finally:
            os.unlink(path)  # the mapping stays; nothing is left on disk
    except OSError as exc:
        raise NativeUnavailable(f"could not load the compiled library: {exc}") from exc


#: Each posted scene leaves a library (~16 kB) behind; past this many the oldest go.
MAX_LIBRARIES = 2000


def _prune(folder: Path) -> None:
    """Keep the cache bounded; a library in use stays mapped even when its file is removed."""
    libraries = sorted(folder.glob("rhs-*.so"), key=lambda f: f.stat().st_mtime)
    for old in libraries[: max(0, len(libraries) - MAX_LIBRARIES)]:
        old.unlink(missing_ok=True)
        old.with_suffix(".json").unlink(missing_ok=True)


def _c_array(name: str, values: np.ndarray) -> str:
    values = np.asarray(values, dtype=float)
    dims = "".join(f"[{d}]" for d in values.shape)

    def rows(v: np.ndarray) -> str:
        if v.ndim == 1:
            return "{" + ", ".join(repr(float(x)) for x in v) + "}"
        return "{" + ",\n  ".join(rows(r) for r in v) + "}"

    return f"static const double {name}{dims} = {rows(values)};\n"


def kernel_source() -> str:
    """dop853.c with scipy's DOP853 tableau emitted in front of it."""
    prelude = "".join(
        _c_array(name, values)
        for name, values in (
            ("LAB_A", tableau.A),
            ("LAB_B", tableau.B),
            ("LAB_C", tableau.C),
            ("LAB_E3", tableau.E3),
            ("LAB_E5", tableau.E5),
            ("LAB_D", tableau.D),
        )
    )
    body = (Path(__file__).parent / "dop853.c").read_text()
    return "/* generated: scipy's DOP853 coefficients */\n" + prelude + body


@functools.lru_cache(maxsize=1)
def _kernel() -> ctypes.CDLL:
    lib = _build(kernel_source(), "dop853")
    fn = lib.lab_dop853
    fn.restype = ctypes.c_int
    fn.argtypes = [
        ctypes.c_void_p,  # rhs
        ctypes.c_void_p,  # p
        ctypes.c_int,  # n
        ctypes.c_void_p,  # y0
        ctypes.c_void_p,  # t_out
        ctypes.c_int,  # n_out
        ctypes.c_void_p,  # y_out
        ctypes.c_double,  # rtol
        ctypes.c_double,  # atol
        ctypes.c_long,  # max_steps
        ctypes.c_double,  # max_seconds
        ctypes.POINTER(_Result),
    ]
    return lib


def available() -> str | None:
    """None when compiled integration works here, else the reason it does not."""
    try:
        _kernel()
    except NativeUnavailable as exc:
        _kernel.cache_clear()  # a compiler installed later is picked up on the next call
        return str(exc)
    return None


# --- generated right-hand sides -------------------------------------------------------------

_C_FUNCTIONS = {
    "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sinh", "cosh", "tanh", "asinh",
    "acosh", "atanh", "exp", "log", "sqrt", "cbrt", "fabs", "pow", "fmin", "fmax", "floor",
    "ceil", "M_PI", "M_E", "M_SQRT2", "M_LN2", "M_LN10", "M_PI_2", "M_PI_4", "M_1_PI",
    "M_2_PI", "M_2_SQRTPI", "M_SQRT1_2", "M_LOG2E", "M_LOG10E", "INFINITY", "NAN",
}  # fmt: skip
_IDENTIFIER = re.compile(r"[A-Za-z_]\w*")
_ALLOWED_NAME = re.compile(r"x\d+|[typab]|dy|const|double")


class _Printer(C99CodePrinter):
    """C99 with small integer powers as products: pow(x, 2) is a library call at -O2."""

    def _print_Pow(self, expr):  # noqa: N802 (sympy's printer protocol)
        base, exp = expr.base, expr.exp
        if exp.is_Integer and 1 < abs(int(exp)) <= 4:
            b = self.parenthesize(base, 100)
            prod = "*".join([b] * abs(int(exp)))
            return f"({prod})" if exp > 0 else f"(1.0/({prod}))"
        if exp == -1:
            return f"(1.0/{self.parenthesize(base, 100)})"
        return super()._print_Pow(expr)


def _checked(code: str) -> str:
    """Refuse printed C that names anything but state, parameters, temporaries and libm."""
    for name in _IDENTIFIER.findall(re.sub(r"\d+\.\d*(e[-+]?\d+)?|\d+e[-+]?\d+", "0", code)):
        if name not in _C_FUNCTIONS and not _ALLOWED_NAME.fullmatch(name):
            raise NativeUnavailable(f"cannot generate C for '{name}'")
    return code


_SOLVE = """
/* Gaussian elimination with partial pivoting, in place: a (n×n, row-major) x = b -> b. */
static int lab_solve(int n, double *a, double *b) {
    for (int c = 0; c < n; c++) {
        int piv = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(a[r * n + c]) > fabs(a[piv * n + c])) piv = r;
        if (!(fabs(a[piv * n + c]) > 0.0)) return 1;
        if (piv != c) {
            for (int j = 0; j < n; j++) {
                double s = a[c * n + j]; a[c * n + j] = a[piv * n + j]; a[piv * n + j] = s;
            }
            double s = b[c]; b[c] = b[piv]; b[piv] = s;
        }
        for (int r = c + 1; r < n; r++) {
            double m = a[r * n + c] / a[c * n + c];
            for (int j = c; j < n; j++) a[r * n + j] -= m * a[c * n + j];
            b[r] -= m * b[c];
        }
    }
    for (int r = n - 1; r >= 0; r--) {
        double s = b[r];
        for (int j = r + 1; j < n; j++) s -= a[r * n + j] * b[j];
        b[r] = s / a[r * n + r];
    }
    return 0;
}
"""


def _expr(e: sp.Basic | int | float) -> sp.Basic:
    """Sympy expressions pass; plain numbers become sympy numbers (never text: no sympify)."""
    if isinstance(e, sp.Basic):
        return e
    return sp.Integer(e) if isinstance(e, int) else sp.Float(float(e))


def rhs_source(
    args: Sequence[sp.Symbol],
    n: int,
    power: sp.Expr | Sequence[sp.Expr],
    accelerations: Sequence[sp.Expr] | None = None,
    mass: Sequence[sp.Expr] | None = None,
    forcing: Sequence[sp.Expr] | None = None,
) -> str:
    """C for dy/dt with y = [q (n), q̇ (n), W_NC, ...]; args = [t, q..., q̇..., params...].

    `power` is the rate of the extra state (the power of the non-conservative forces), or a list
    of rates, one extra state each (a drive's −∂L/∂t rides along too).

    With `accelerations` q̈ is printed directly; otherwise M (row-major) and f are printed and
    M q̈ = f is solved in C (a zero pivot returns RHS_SINGULAR).
    """
    slots = {args[0]: sp.Symbol("t")}
    slots |= {a: sp.Symbol(f"y[{i}]") for i, a in enumerate(args[1 : 2 * n + 1])}
    slots |= {a: sp.Symbol(f"p[{k}]") for k, a in enumerate(args[2 * n + 1 :])}
    outputs = [*accelerations] if accelerations is not None else [*mass, *forcing]
    rates = list(power) if isinstance(power, (list, tuple)) else [power]
    exprs = [_expr(e).xreplace(slots) for e in [*outputs, *rates]]
    stray = set().union(*(e.free_symbols for e in exprs)) - set(slots.values())
    if stray:
        raise NativeUnavailable(f"unexpected symbols {sorted(map(str, stray))}")
    temps, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("x"))
    try:
        return _assemble(
            n, len(args) - 2 * n - 1, temps, reduced, accelerations is not None, len(rates)
        )
    except PrintMethodNotImplementedError as exc:
        raise NativeUnavailable(f"cannot generate C: {str(exc).splitlines()[0]}") from exc


def _assemble(
    n: int, n_params: int, temps: list, reduced: list, solved: bool, extras: int = 1
) -> str:
    printer = _Printer({"strict": True})
    lines = [f"    const double {s} = {printer.doprint(e)};" for s, e in temps]
    if solved:
        lines += [f"    dy[{n + i}] = {printer.doprint(e)};" for i, e in enumerate(reduced[:n])]
    else:
        lines += [f"    a[{i}] = {printer.doprint(e)};" for i, e in enumerate(reduced[: n * n])]
        forcing = reduced[n * n : n * n + n]
        lines += [f"    b[{i}] = {printer.doprint(e)};" for i, e in enumerate(forcing)]
    for i, e in enumerate(reduced[len(reduced) - extras :]):
        lines.append(f"    dy[{2 * n + i}] = {printer.doprint(e)};")
    body = _checked("\n".join(lines))
    head = [f"    dy[{i}] = y[{n + i}];" for i in range(n)]
    if not solved:
        solve = [
            f"    if (lab_solve({n}, a, b)) return {RHS_SINGULAR};",
            *(f"    dy[{n + i}] = b[{i}];" for i in range(n)),
        ]
        head.insert(0, f"    double a[{n * n}], b[{n}];")
    else:
        solve = []
    return "\n".join(
        [
            f"/* lab: dim {2 * n + extras} params {n_params} */",
            "#include <math.h>",
            "" if solved else _SOLVE,
            "int lab_rhs(double t, const double *y, const double *p, double *dy) {",
            "    (void)t; (void)p;",
            *head,
            body,
            *solve,
            "    return 0;",
            "}",
            "",
        ]
    )


_GENERATED_LINE = re.compile(
    r"    (?:const double x\d+|dy\[\d+\]|a\[\d+\]|b\[\d+\]) = ([^;{}#\"'/\\]|/(?![/*]))+;"
    r"|    double a\[\d+\], b\[\d+\];"
    rf"|    if \(lab_solve\(\d+, a, b\)\) return {RHS_SINGULAR};"
)
_RHS_HEAD = [
    "#include <math.h>",
    "int lab_rhs(double t, const double *y, const double *p, double *dy) {",
    "    (void)t; (void)p;",
]


def is_generated_source(source: object) -> bool:
    """Is ``source`` what `rhs_source` prints, line by line? The check a right-hand side's C
    would have to pass before it is compiled if it ever came from outside this process (none
    does today: the source is not shared through the cache): assignments of whitelisted
    expressions to numbered slots, the fixed solver, nothing else (no other function, directive,
    comment or call outside libm)."""
    if not isinstance(source, str):
        return False
    first, _, rest = source.replace(_SOLVE, "\n", 1).partition("\n")
    lines = [line for line in rest.split("\n") if line]
    if _SHAPE.fullmatch(first) is None:
        return False
    if lines[:3] != _RHS_HEAD or lines[-2:] != ["    return 0;", "}"]:
        return False
    body = lines[3:-2]
    if not all(_GENERATED_LINE.fullmatch(line) for line in body):
        return False
    try:
        _checked("\n".join(line.split(" = ", 1)[-1] for line in body if " = " in line))
    except NativeUnavailable:
        return False
    return True


@functools.lru_cache(maxsize=128)
def _rhs_library(source: str) -> ctypes.CDLL:
    return _build(source, "rhs")


@dataclass
class NativeRhs:
    """A compiled right-hand side bound to parameter values (kept alive with its library)."""

    library: ctypes.CDLL
    params: np.ndarray
    dim: int

    @property
    def address(self) -> int:
        return ctypes.cast(self.library.lab_rhs, ctypes.c_void_p).value

    def __call__(self, t: float, y: np.ndarray) -> np.ndarray:
        """The same function from Python (tests compare it with the lambdified one)."""
        y = np.ascontiguousarray(y, dtype=float)
        out = np.empty(self.dim)
        fn = ctypes.cast(self.library.lab_rhs, RHS_SIGNATURE)
        code = fn(t, _ptr(y), _ptr(self.params), _ptr(out))
        if code:
            raise ArithmeticError(f"the compiled right-hand side returned code {code}")
        return out


_SHAPE = re.compile(r"/\* lab: dim (\d+) params (\d+) \*/")


def compile_rhs(source: str, params: Sequence[float], dim: int) -> NativeRhs:
    """Build (or load from the disk cache) a generated right-hand side; bind parameters.

    The C reads params and writes dy by index, so the shapes are checked against the ones
    `rhs_source` recorded: a mismatch here would be memory corruption there."""
    shape = _SHAPE.match(source)
    if shape is None or (int(shape[1]), int(shape[2])) != (dim, len(params)):
        raise ValueError(
            f"the source is not a right-hand side of {dim} states, {len(params)} params"
        )
    lib = _rhs_library(source)
    return NativeRhs(lib, np.ascontiguousarray(params, dtype=float), dim)


def _ptr(a: np.ndarray):
    return a.ctypes.data_as(ctypes.POINTER(ctypes.c_double))


# --- the integrator -------------------------------------------------------------------------


@dataclass
class NativeRun:
    status: int
    y: np.ndarray  # (samples reached, dim)
    nfev: int
    nsteps: int
    nrejected: int
    t_reached: float
    t_bad: float
    rhs_code: int
    error: BaseException | None  # what a Python right-hand side raised, if it did


def dop853(
    rhs: NativeRhs | Callable[[float, np.ndarray], np.ndarray],
    y0: np.ndarray,
    t_eval: np.ndarray,
    *,
    rtol: float,
    atol: float,
    max_steps: int,
    max_seconds: float,
) -> NativeRun:
    """Run the C DOP853 loop; a Python callable is called back through ctypes (slower, but the
    same algorithm), a NativeRhs is called directly with the GIL released."""
    lib = _kernel()
    y0 = np.ascontiguousarray(y0, dtype=float)
    t_eval = np.ascontiguousarray(t_eval, dtype=float)
    dim = len(y0)
    y_out = np.zeros((len(t_eval), dim))
    result = _Result()
    failure: list[BaseException] = []
    if isinstance(rhs, NativeRhs):
        if rhs.dim != dim:
            raise ValueError(f"the compiled right-hand side has {rhs.dim} states, y0 has {dim}")
        address, params, keep = rhs.address, rhs.params, None
    else:

        def callback(t, y, p, dy) -> int:
            try:
                d = np.ascontiguousarray(rhs(t, np.array(y[:dim])), dtype=float)
                if d.shape != (dim,):
                    raise ValueError(f"the right-hand side returned shape {d.shape}")
                ctypes.memmove(dy, d.ctypes.data, 8 * dim)
                return 0
            except BaseException as exc:  # noqa: BLE001 — must not cross the C frame
                failure.append(exc)
                return 1

        keep = RHS_SIGNATURE(callback)
        address, params = ctypes.cast(keep, ctypes.c_void_p).value, np.zeros(1)
    status = lib.lab_dop853(
        address,
        params.ctypes.data,
        dim,
        y0.ctypes.data,
        t_eval.ctypes.data,
        len(t_eval),
        y_out.ctypes.data,
        rtol,
        atol,
        max_steps,
        max_seconds,
        ctypes.byref(result),
    )
    del keep
    return NativeRun(
        status,
        y_out[: result.n_out],
        result.nfev,
        result.nsteps,
        result.nrejected,
        result.t,
        result.t_bad,
        result.rhs_code,
        failure[0] if failure else None,
    )
