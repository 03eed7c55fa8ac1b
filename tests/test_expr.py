"""The whitelist parser: every rule of the plain-text convention, and hostile input refused fast."""

from __future__ import annotations

import time

import pytest
import sympy as sp
from sympy.physics.vector import ReferenceFrame, dynamicsymbols

from mechanics.expr import (
    FUNCTIONS,
    MAX_DEPTH,
    MAX_LENGTH,
    ExprError,
    free_names,
    parse,
    to_latex,
    to_plain,
)

t = dynamicsymbols._t
theta, phi = dynamicsymbols("theta phi")
m, g, l1 = sp.Symbol("m", positive=True), sp.Symbol("g"), sp.Symbol("l1")
NAMES = {
    "theta": theta, "theta_dot": theta.diff(t), "theta_ddot": theta.diff(t, 2),
    "phi": phi, "phi_dot": phi.diff(t), "t": t, "m": m, "g": g, "l1": l1,
}  # fmt: skip


def p(text):
    return parse(text, NAMES, field="f")


def refused(text, names=NAMES) -> ExprError:
    with pytest.raises(ExprError) as err:
        parse(text, names, field="f")
    return err.value


class fast:  # noqa: N801 - reads as `with fast():`
    """Hostile input must fail long before it could tie up a server worker."""

    def __enter__(self):
        self.start = time.perf_counter()

    def __exit__(self, *exc):
        assert time.perf_counter() - self.start < 0.1


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("m + g", m + g),
        ("m - g", m - g),
        ("m*g", m * g),
        ("m/g", m / g),
        ("m**2", m**2),
        ("-m", -m),
        ("+m", m),
        ("m + g*l1**2", m + g * l1**2),  # precedence
        ("(m + g)*l1", (m + g) * l1),
        ("2", sp.Integer(2)),
        ("0.5*m", m / 2),  # short decimals are exact
        ("1e-3*g", g / 1000),
        ("pi*m", sp.pi * m),
        ("theta_dot**2", theta.diff(t) ** 2),
        ("theta_ddot", theta.diff(t, 2)),
        ("t*g", t * g),
        ("m - g - l1", sp.Add(m, -g, -l1)),
        ("m/g/l1", m / (g * l1)),
        ("g**-2", sp.Pow(g, -2)),
        ("g**2**3", g**8),  # ** is right-associative
        ("-(m + g)", -m - g),
        ("  m  ", m),
        ("(m +\n\tg)", m + g),  # newlines and tabs inside an expression are spaces
        ("2*pi*sqrt(l1/g)", 2 * sp.pi * sp.sqrt(l1 / g)),
    ],
)
def test_operators_numbers_and_names(text, expected):
    assert p(text) == expected


@pytest.mark.parametrize(
    ("name", "function"),
    [
        ("sin", sp.sin),
        ("cos", sp.cos),
        ("tan", sp.tan),
        ("cot", sp.cot),
        ("sec", sp.sec),
        ("csc", sp.csc),
        ("asin", sp.asin),
        ("acos", sp.acos),
        ("atan", sp.atan),
        ("sinh", sp.sinh),
        ("cosh", sp.cosh),
        ("tanh", sp.tanh),
        ("exp", sp.exp),
        ("log", sp.log),
        ("sqrt", sp.sqrt),
        ("abs", sp.Abs),
        ("sign", sp.sign),
    ],
)
def test_each_whitelisted_function(name, function):
    assert p(f"{name}(theta)") == function(theta)


def test_atan2_takes_two_arguments():
    assert p("atan2(m, g)") == sp.atan2(m, g)


@pytest.mark.parametrize(
    ("text", "says"),
    [
        ("lenght*m", "unknown name 'lenght'"),
        ("m^2", "**"),
        ("m.__class__", "__"),
        ("__import__('os').system('ls')", ""),
        ("lambda: 1", ""),
        ("[1, 2]", ""),
        ("m[0]", ""),
        ("'text'", ""),
        ("1 < 2", ""),
        ("m and g", ""),
        ("sin(x=1)", ""),
        ("sin(1, 2)", "takes 1 argument"),
        ("atan2(1)", "takes 2 arguments"),
        ("theta(1)", "function 'theta' is not allowed"),
        ("m(g)", "write '*'"),
        ("(m*g)(1)", "listed functions"),
        ("foo(1)", "function 'foo' is not allowed"),
        ("eval('1')", ""),
        ("m; g", "not allowed"),
        ("m\ng", ""),
        ("", "empty"),
        ("   ", "empty"),
        ("1e999", "finite"),
        ("m/0", "division by zero"),
        ("sin", "needs arguments"),
        ("m if g else t", "'if'"),
        ("m.real", "attribute access is not allowed"),
        ("not m", "'not'"),
        ("True", "'True'"),
        ("m // 2", "'//'"),
        ("m % 2", "'%'"),
        ("m @ g", "'@'"),
        ("1, 2", "comma"),
        ("1j", "complex"),
        ("...", "'...'"),
        ("sin(**m)", "keyword"),
        ("sin(*m)", "'*'"),
        ("1 +* 2", "syntax error"),
        ("(m + 1", "never closed"),
        ("m + 1)", "')'"),
        ("θ", "'θ'"),
        ("m\u00a0+ 1", "character"),
        ("m/(g - g)", "division by zero"),
        ("log(0)", "finite"),
        ("0**-1", "finite"),
        ("1e308*1e308", "finite"),
        ("1e300*1e300*m", "finite"),
        ("exp(1000)", "finite"),
        ("m**-100", "exponent"),
        ("(2**60)**60", "too large"),
    ],
)
def test_everything_else_is_refused_with_the_field_named(text, says):
    with pytest.raises(ExprError) as err:
        p(text)
    assert err.value.field == "f"
    assert says in err.value.message


@pytest.mark.parametrize("value", [float("nan"), float("inf"), True, None, [1]])
def test_non_text_inputs_are_refused(value):
    with pytest.raises(ExprError):
        parse(value, NAMES)


@pytest.mark.parametrize(
    "text",
    [
        "9**9**9**9",
        "2**1000",
        "10**400",
        "x" * 100_000,
        "(" * 1000 + "1" + ")" * 1000,
        "-" * 5000 + "1",
        "1" * 40,
        "+".join(["m"] * 1500),
    ],
)
def test_hostile_sizes_are_refused_fast(text):
    start = time.perf_counter()
    with pytest.raises(ExprError):
        p(text)
    assert time.perf_counter() - start < 0.1


def test_free_names():
    assert free_names("m*g*l*cos(theta) + pi") == {"m", "g", "l", "theta"}
    assert free_names("2 + foo(3)") == {"foo"}
    for text in ["__import__('os')", "m^2", "x" * 100_000]:
        with pytest.raises(ExprError):
            free_names(text)


@pytest.mark.parametrize(
    "expr",
    [
        m * g * l1 * sp.cos(theta),
        m * l1**2 * theta.diff(t) ** 2 / 2,
        theta.diff(t, 2) + g / l1 * sp.sin(theta),
        sp.Abs(theta.diff(t)) * sp.sign(phi.diff(t)),
        sp.atan2(sp.sin(theta), sp.cos(phi)),
        sp.Rational(3, 7) * m,
        m**-2 * g,
        sp.sqrt(g / l1),
        sp.exp(-t * g) * sp.cos(2 * t),
        sp.log(m) - sp.tan(theta) ** 3,
        sp.Float(0.123456789012, 15) * g,
        sp.pi * m / 4,
        sp.sinh(m) * sp.cosh(g) / sp.tanh(l1) + sp.asin(g) + sp.acos(m) + sp.atan(l1),
        sp.sec(theta) * sp.csc(phi) * sp.cot(t),
        2 * sp.pi * (l1 + phi.diff(t)) ** 3,
        sp.E * m,
        sp.Rational(-3, 7) * g**-3 + 1 / sp.sqrt(m),
    ],
)
def test_plain_text_round_trips(expr):
    assert sp.simplify(p(to_plain(expr)) - expr) == 0


def test_plain_text_uses_the_convention():
    assert to_plain(theta.diff(t) ** 2 * m) == "m*theta_dot**2"
    assert to_plain(theta.diff(t, 2)) == "theta_ddot"
    assert to_plain(sp.Abs(theta)) == "abs(theta)"
    assert to_plain(theta) == "theta"
    assert to_plain(sp.sqrt(g)) == "sqrt(g)"
    assert to_plain(m * g * l1 / 2) == "g*l1*m/2"
    assert to_plain(sp.Float(0.1) * g) == "0.1*g"
    assert to_plain([g, [m, 1]]) == "[g, [m, 1]]"


def test_latex_uses_dot_notation_and_greek_letters():
    assert r"\dot{\theta}" in to_latex(theta.diff(t))
    assert r"\ddot{\theta}" in to_latex(theta.diff(t, 2))
    assert to_latex(theta) == r"\theta"
    assert "l_{1}" in to_latex(l1)
    assert to_latex(sp.Symbol("l_2")) == "l_{2}"
    for name in ["phi", "omega", "Omega", "alpha", "mu"]:
        assert to_latex(sp.Symbol(name)) == "\\" + name


def test_latex_accepts_vectors():
    N = ReferenceFrame("N")
    text = to_latex(l1 * sp.sin(theta) * N.x)
    assert r"\theta" in text and r"\mathbf{\hat{n}_x}" in text


def test_whitelist_is_exactly_the_documented_functions():
    documented = "sin cos tan cot sec csc asin acos atan atan2 sinh cosh tanh exp log sqrt abs sign"
    assert set(FUNCTIONS) == set(documented.split())


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("2.0", sp.Integer(2)),
        ("1e6", sp.Integer(1_000_000)),
        ("9.81", sp.Rational(981, 100)),
        ("2.5e-3", sp.Rational(1, 400)),
        ("0.123456", sp.Rational(123456, 1_000_000)),
    ],
)
def test_short_decimals_are_exact(text, expected):
    value = p(text)
    assert value == expected and value.is_Rational


def test_long_or_tiny_decimals_stay_floats():
    long = p("0.1234567")
    assert isinstance(long, sp.Float) and abs(long - sp.Float("0.1234567", 15)) < 1e-15
    tiny = p("6.674e-11")
    assert isinstance(tiny, sp.Float) and abs(tiny / sp.Float("6.674e-11", 15) - 1) < 1e-14


def test_python_numbers_are_converted():
    assert isinstance(parse(3, NAMES), sp.Integer) and parse(3, NAMES) == 3
    assert parse(0.25, NAMES) == sp.Rational(1, 4)
    assert parse(-2.0, NAMES) == sp.Integer(-2)
    assert isinstance(parse(3.14159265358979, NAMES), sp.Float)
    assert "finite" in refused(float("nan")).message
    assert "digits" in refused(10**40).message


def test_error_carries_field_message_position_and_str():
    err = refused("m*lenght")
    assert (err.field, err.position) == ("f", 2)
    assert str(err) == "f: " + err.message
    assert isinstance(err, ValueError)
    plain = ExprError("bad")
    assert (str(plain), plain.field, plain.position) == ("bad", "", None)


def test_unknown_name_lists_the_known_ones_when_few():
    err = refused("lenght", names={"length": l1, "mass": m})
    assert "'lenght'" in err.message and "length" in err.message and "mass" in err.message


def test_positions_point_into_the_original_text():
    assert refused("m ^ 2").position == 2
    assert refused("  1 +* 2").position == 5
    assert refused("m + lenght").position == 4
    assert refused("(m + 1").position == 0


def test_long_sums_are_not_deep_nesting():
    """An equation of motion can have many more terms than MAX_DEPTH."""
    symbols = sp.symbols(f"a0:{MAX_DEPTH * 4}")
    names = {str(s): s for s in symbols}
    text = " + ".join(f"{s}*{s}" for s in symbols[:-1]) + f" - {symbols[-1]}"
    assert parse(text, names) == sp.Add(*(s**2 for s in symbols[:-1])) - symbols[-1]
    assert parse("*".join(map(str, symbols)), names) == sp.Mul(*symbols)


def test_depth_limits():
    assert p("(" * MAX_DEPTH + "m" + ")" * MAX_DEPTH) == m
    for text in [
        "(" * (MAX_DEPTH + 1) + "m" + ")" * (MAX_DEPTH + 1),
        "sin(" * (MAX_DEPTH + 1) + "m" + ")" * (MAX_DEPTH + 1),
        "-" * 500 + "m",
    ]:
        with fast():
            assert "deeper" in refused(text).message


def test_power_towers_and_huge_text_fail_fast():
    for text in ["9**9**9", "2**2**2**2**2**2", "(9**9)**(9**9)"]:
        with fast():
            refused(text)
    with fast():
        assert str(MAX_LENGTH) in refused("1+" * 50_000 + "1").message
