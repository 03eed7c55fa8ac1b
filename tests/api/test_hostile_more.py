"""Found by a second hostile play-test (share links, predictions, nested powers, live modules,
parse errors): each bad input is a 4xx in the one error shape naming its field, with a message
that says what is wrong, never a 500 and never a wrong answer."""

from __future__ import annotations

import base64
import json
import math
import zlib

import pytest
from fastapi.testclient import TestClient

from app.main import app
from mechanics.scenes import load_scene, scene_ids

client = TestClient(app)


def one_problem(response, status: int) -> dict[str, str]:
    assert response.status_code == status, response.text
    (problem,) = response.json()["detail"]
    assert set(problem) == {"field", "message"}
    return problem


def token_of(state: dict) -> str:
    """A hand-made token (the format: 'z' + base64url of zlib of JSON), as an attacker makes it."""
    raw = zlib.compress(json.dumps(state).encode())
    return "z" + base64.urlsafe_b64encode(raw).decode().rstrip("=")


# --- 1. share links: the scene must exist and its values must be the scene's -----------------

#: The page's own query keys (static/js/controls.js writeQuery, scene.js), written out here.
PAGE_KEYS = ["method", "method_b", "tol", "atol", "dt", "t_end", "compare", "lecture", "phase"]
PAGE_KEYS += ["step", "from", "fps"]


def test_a_share_of_an_unknown_scene_is_a_404_naming_scene_id():
    r = client.post("/api/v1/export/share", json={"scene_id": "no_such_scene"})
    problem = one_problem(r, 404)
    assert problem["field"] == "scene_id"
    assert "unknown scene 'no_such_scene'" in problem["message"]
    assert "GET /api/v1/scenes" in problem["message"]


@pytest.mark.parametrize("name", ["t_end", "method", "step", "dt", "lecture"])
def test_a_share_with_a_parameter_named_like_a_page_setting_is_refused(name):
    state = {"scene_id": "simple_pendulum", "parameters": {name: 3.0}}
    problem = one_problem(client.post("/api/v1/export/share", json=state), 422)
    assert problem["field"] == f"parameters.{name}"
    assert "setting of the page" in problem["message"] and name in problem["message"]


def test_a_share_with_values_the_scene_does_not_have_names_each():
    state = {
        "scene_id": "simple_pendulum",
        "parameters": {"k": 1.0},
        "initial": {"phi": 0.5, "theta": 1.0},
        "phase": "x",
    }
    r = client.post("/api/v1/export/share", json=state)
    assert r.status_code == 422, r.text
    problems = {p["field"]: p["message"] for p in r.json()["detail"]}
    assert set(problems) == {"parameters.k", "initial.phi", "phase"}
    # the pendulum's own names (its TOML: m, l, g; theta) are listed to choose from
    assert "m" in problems["parameters.k"] and "g" in problems["parameters.k"]
    assert "theta_dot" in problems["initial.phi"]
    assert "theta" in problems["phase"]


@pytest.mark.parametrize(
    "state, field, says",
    [
        ({"scene_id": "no_such_scene"}, "token.scene_id", "unknown scene"),
        (
            {"scene_id": "simple_pendulum", "parameters": {"t_end": 3}},
            "token.parameters.t_end",
            "page",
        ),
        (
            {"scene_id": "simple_pendulum", "parameters": {"step": 2}},
            "token.parameters.step",
            "page",
        ),
        ({"scene_id": "simple_pendulum", "initial": {"method": 1}}, "token.initial.method", "page"),
        (
            {"scene_id": "simple_pendulum", "parameters": {"k": 1}},
            "token.parameters.k",
            "no parameter",
        ),
    ],
)
def test_a_hand_edited_token_is_refused_when_it_is_opened(state, field, says):
    token = token_of(state)
    for url in (f"/api/v1/export/share/{token}", f"/s/{token}"):
        problem = one_problem(client.get(url, follow_redirects=False), 422)
        assert problem["field"] == field
        assert says in problem["message"]


def test_a_posted_specs_share_checks_its_overrides_against_that_spec():
    spec = load_scene("simple_pendulum")
    good = client.post("/api/v1/export/share", json={"scene": spec, "parameters": {"l": 2.0}})
    assert good.status_code == 200, good.text
    r = client.post("/api/v1/export/share", json={"scene": spec, "parameters": {"L": 2.0}})
    problem = one_problem(r, 422)
    assert problem["field"] == "parameters.L" and "posted scene" in problem["message"]


def test_no_built_in_scene_names_a_value_like_a_page_setting():
    """Otherwise its own links could not be told apart from the page's settings."""
    for scene_id in scene_ids():
        spec = load_scene(scene_id)
        names = set(spec.get("parameters") or {}) | set(spec["coordinates"])
        names |= {f"{q}_dot" for q in spec["coordinates"]}
        assert not names & set(PAGE_KEYS), scene_id


def test_a_honest_builtin_share_still_opens_its_page():
    state = {"scene_id": "double_pendulum", "parameters": {"m2": 2.0}, "initial": {"theta1": 1}}
    link = client.post("/api/v1/export/share", json={**state, "phase": "theta2"}).json()
    opened = client.get(link["url"], follow_redirects=False)
    assert opened.status_code == 303
    assert opened.headers["location"].startswith("/scenes/double_pendulum?m2=2.0&theta1=1.0")


# --- 4. 404s of the live modules ------------------------------------------------------------


def test_the_live_module_of_an_unknown_scene_says_so_and_where_the_ids_are():
    for url in ("/api/v1/scenes/no_such_scene/live.js", "/api/v1/scenes/no_such_scene/live"):
        problem = one_problem(client.get(url), 404)
        assert problem["field"] == "scene_id"
        assert "unknown scene 'no_such_scene'" in problem["message"]
        assert "GET /api/v1/scenes" in problem["message"]


def test_every_unknown_scene_404_reads_the_same():
    """/derive, /check (through the pool's gate), /simulate and live.js say it in one sentence."""
    answers = [
        client.get("/api/v1/scenes/nope/live.js"),
        client.post("/api/v1/derive", json={"scene_id": "nope"}),
        client.post("/api/v1/check", json={"scene_id": "nope", "quantity": "T", "answer": "1"}),
        client.post("/api/v1/simulate", json={"scene_id": "nope"}),
    ]
    messages = {one_problem(r, 404)["message"] for r in answers}
    assert messages == {"unknown scene 'nope' (GET /api/v1/scenes lists the scene ids)"}


def test_a_missing_posted_module_names_its_digest_not_a_scene():
    problem = one_problem(client.get("/api/v1/scenes/live/0123456789abcdef.js"), 404)
    assert problem["field"] == "digest"
    assert "post the scene again" in problem["message"]


# --- 2. predict (and simulate, precision): the field and the words of a bad number ----------


def predict(**fields):
    body = {"scene_id": "simple_pendulum", "quantity": "eom", "coordinate": "theta"}
    body["answer"] = "theta'' + g/l sin(theta) = 0"
    return client.post("/api/v1/check/predict", json={**body, **fields})


def nan_post(url: str, body: str):
    """Python's JSON reader takes NaN and Infinity: a client may send them."""
    return client.post(url, content=body, headers={"content-type": "application/json"})


@pytest.mark.parametrize("literal", ["NaN", "Infinity", "-Infinity"])
def test_a_non_finite_t_end_is_said_to_be_not_finite(literal):
    body = (
        '{"scene_id": "simple_pendulum", "quantity": "accel", "coordinate": "theta", '
        f'"answer": "-g/l sin(theta)", "t_end": {literal}}}'
    )
    problem = one_problem(nan_post("/api/v1/check/predict", body), 422)
    assert problem["field"] == "t_end"
    assert "finite number" in problem["message"] and "10" not in problem["message"]


@pytest.mark.parametrize(
    "url, body, field",
    [
        ("/api/v1/simulate", '{"scene_id": "simple_pendulum", "t_end": NaN}', "t_end"),
        ("/api/v1/simulate", '{"scene_id": "simple_pendulum", "fps": Infinity}', "fps"),
        ("/api/v1/simulate", '{"scene_id": "simple_pendulum", "method": "rk4", "dt": NaN}', "dt"),
        ("/api/v1/simulate", '{"scene_id": "simple_pendulum", "rtol": NaN}', "rtol"),
        (
            "/api/v1/simulate",
            '{"scene_id": "simple_pendulum", "initial": {"theta": NaN}}',
            "initial.theta",
        ),
        ("/api/v1/precision", '{"scene_id": "simple_pendulum", "t_end": NaN}', "t_end"),
        ("/api/v1/precision", '{"scene_id": "simple_pendulum", "steps": [0.1, NaN]}', "steps[1]"),
        (
            "/api/v1/precision",
            '{"scene_id": "simple_pendulum", "tolerances": [Infinity]}',
            "tolerances[0]",
        ),
        (
            "/api/v1/precision",
            '{"scene_id": "simple_pendulum", "parameters": {"l": NaN}}',
            "parameters.l",
        ),
        (
            "/api/v1/equilibria",
            '{"scene_id": "simple_pendulum", "parameters": {"g": NaN}}',
            "parameters.g",
        ),
        (
            "/api/v1/check/predict",
            '{"scene_id": "simple_pendulum", "quantity": "T", "answer": "m", '
            '"initial": {"theta": NaN}}',
            "initial.theta",
        ),
    ],
)
def test_every_non_finite_number_is_said_to_be_not_finite_on_its_field(url, body, field):
    problem = one_problem(nan_post(url, body), 422)
    assert problem["field"] == field
    assert "finite number" in problem["message"]


def test_a_zero_length_pendulum_blames_the_parameter_not_the_initial_state():
    """With l = 0 the pendulum's m l² θ̈ has no inertia: θ̈ is undetermined for any start."""
    problem = one_problem(predict(parameters={"l": 0}), 422)
    assert problem["field"] == "parameters.l"
    assert "l = 0" in problem["message"] and "cannot start" in problem["message"]


def test_a_zero_mass_among_harmless_overrides_is_the_one_blamed():
    problem = one_problem(predict(parameters={"g": 3.0, "m": 0, "l": 2.0}), 422)
    assert problem["field"] == "parameters.m" and "m = 0" in problem["message"]


def test_a_singular_start_of_the_coordinates_blames_that_initial_value():
    """The spherical pendulum's φ has no inertia at θ = 0 (m l² sin²θ φ̈): the start is blamed."""
    body = {
        "scene_id": "spherical_pendulum",
        "quantity": "accel",
        "coordinate": "theta",
        "answer": "-g/l sin(theta)",
        "initial": {"theta": 0.0},
    }
    problem = one_problem(client.post("/api/v1/check/predict", json=body), 422)
    assert problem["field"] == "initial.theta"
    assert "theta = 0" in problem["message"]


# --- 3. nested powers and exponentials: bounded in total, not only one exponent at a time ----


def check(answer: str, quantity: str = "T", scene_id: str = "simple_pendulum"):
    body = {"scene_id": scene_id, "quantity": quantity, "answer": answer}
    return client.post("/api/v1/check", json=body)


@pytest.mark.parametrize(
    "answer, degree",
    [
        ("((theta)**64)**64", 64 * 64),
        ("((theta_dot**2)**8)**8", 2 * 8 * 8),
        ("((sin(theta)+cos(theta))**64)**64", 64 * 64),
        ("(((theta+1)**4)**4)**8", 4 * 4 * 8),
        ("theta**40*theta**40", 40 + 40),  # one base: sympy writes it theta**80
        ("m*" * 70 + "m", 71),
    ],
)
def test_powers_past_degree_64_in_total_are_a_422_on_answer(answer, degree):
    problem = one_problem(check(answer), 422)
    assert problem["field"] == "answer"
    assert f"degree {degree}" in problem["message"] and "64" in problem["message"]


@pytest.mark.parametrize(
    "answer",
    [
        "(theta**64)**64**2",  # 64**2 is one exponent of 4096
        "theta**(64*64)",
        "theta_dot**(8**3)",
    ],
)
def test_one_exponent_past_64_is_a_422_on_answer(answer):
    problem = one_problem(check(answer), 422)
    assert problem["field"] == "answer" and "exponent too large" in problem["message"]


@pytest.mark.parametrize(
    "answer",
    ["exp(exp(exp(theta)))", "exp(exp(exp(exp(exp(exp(theta_dot))))))", "2**(2**(2**theta))"]
    + ["cosh(sinh(exp(theta_dot)))", "exp(theta_dot**theta**theta)"],
)
def test_exponentials_nested_three_deep_are_a_422_on_answer(answer):
    problem = one_problem(check(answer, "V"), 422)
    assert problem["field"] == "answer"
    assert "exponentials nested" in problem["message"]


def test_predict_refuses_the_same_towers_on_answer():
    for answer in ("((theta)**64)**64", "exp(exp(exp(theta)))"):
        body = {"scene_id": "simple_pendulum", "quantity": "V", "answer": answer}
        problem = one_problem(client.post("/api/v1/check/predict", json=body), 422)
        assert problem["field"] == "answer"


@pytest.mark.parametrize(
    "answer, right",
    [
        ("1/2 m l^2 ((theta_dot)**2)", True),
        ("1/2 m l^2 (theta_dot**2)**2", False),  # θ̇⁴: judged, not refused
        ("1/2 m l^2 theta_dot^2 (sin(theta)**2 + cos(theta)**2)", True),
        ("1/2 m l^2 theta_dot^2 ((sin(theta)**2 + cos(theta)**2)**4)**4", True),  # degree 32
        ("1/2 m l^2 theta_dot^2 exp(exp(theta) - exp(theta))", True),  # exp nested twice
    ],
)
def test_honest_powers_and_exponentials_are_still_judged(answer, right):
    r = check(answer)
    assert r.status_code == 200, r.text
    assert r.json()["correct"] is right


# --- 5. parse errors: a plain sentence, pointing where the fix is typed ----------------------


@pytest.mark.parametrize(
    "answer, at, says",
    [
        # the term missing after a trailing '+' goes after it: "theta +" has 7 characters
        ("theta +", 7, "a term is missing after '+'"),
        ("1/2 m l^2 theta'^2 +", 20, "a term is missing after '+'"),
        ("theta + ", 8, "a term is missing after '+'"),  # at the end, past the space
        ("m*(l+)", 5, "a term is missing after '+'"),  # before the ')', after the '+'
        ("m * * l", 4, "'*' needs a term before it"),  # the second '*' is the one to fix
        ("m*()", 3, "nothing is between '(' and ')'"),  # inside the parentheses
        ("m*(l, g)", 4, "comma"),  # the comma itself
        ("theta))", 5, "')' without a matching '('"),  # the first ')' closes nothing
    ],
)
def test_a_parse_error_points_where_the_fix_goes_in_plain_words(answer, at, says):
    problem = one_problem(check(answer), 422)
    assert problem["field"] == "answer"
    message = problem["message"]
    assert says in message
    assert not message.lower().startswith("syntax") and "syntax error" not in message
    # the message shows the place, counting from 1, with the typed text around it
    assert f"at character {at + 1}:" in message
    shown = message.split(": ", 1)[1] if ": " in message else message
    before = answer[max(0, at - 24) : at].lstrip()
    assert f"{before}⟨here⟩" in shown, (before, shown)


def test_the_parser_alone_points_past_a_trailing_operator():
    from mechanics.expr import ExprError, parse

    for text, at in (("a +", 3), ("a + b *", 7), ("(a -)", 4)):
        with pytest.raises(ExprError) as info:
            parse(text, {"a": 1, "b": 2}, field="f")
        assert info.value.position == at, (text, info.value.position)
        assert info.value.message.startswith("a term is missing after")


# --- found by playing the hostile user: predictions ------------------------------------------


def test_a_start_past_the_blow_up_line_is_refused_not_called_a_blow_up():
    """θ = 1e300 was 'your answer's motion blows up at t = 1e-06 s' for θ̈ = 0, which never
    blows up: the start was already past the |q| < 1e6 line every run is held to."""
    problem = one_problem(predict(initial={"theta": 1e300}), 422)
    assert problem["field"] == "initial.theta"
    assert "1e+06" in problem["message"]


def test_a_comparison_cut_short_says_over_how_long():
    """At θ̇ = 1e5 rad/s the true run needs more than its step cap: 'the same motion' holds only
    over the time it reached, and the summary says so."""
    r = predict(initial={"theta_dot": 1e5}, t_end=5)
    assert r.status_code == 200, r.text
    body = r.json()
    reached = min(body["true"]["reached"], body["student"]["reached"])
    assert reached < 5
    assert f"first {reached:.2f} s only" in body["summary"], body["summary"]


# --- found by playing the hostile user: precision ---------------------------------------------


def test_a_reference_run_broken_by_a_value_names_the_value_not_t_end():
    """g = 1e308: the pendulum's q̈ = −g/l sin θ leaves double precision in the first steps; the
    422 said field 't_end', which no t_end can fix."""
    body = {"scene_id": "simple_pendulum", "methods": ["rk4"], "parameters": {"g": 1e308}}
    problem = one_problem(client.post("/api/v1/precision", json=body), 422)
    assert problem["field"] == "parameters.g"
    assert "g = 1e+308" in problem["message"] and "double precision" in problem["message"]


# --- found by playing the hostile user: exports and path parameters --------------------------


@pytest.mark.parametrize(
    "query, field",
    [
        ("trajectory.csv?tol=0", "tol"),  # the page's key, not /simulate's rtol and atol
        ("run.py?method=Radau&tol=1e-20", "tol"),
        ("run.py?tol=1e-3&atol=5", "atol"),
    ],
)
def test_a_get_exports_tolerance_is_refused_under_the_pages_key(query, field):
    r = client.get(f"/api/v1/export/scenes/simple_pendulum/{query}")
    problem = one_problem(r, 422)
    assert problem["field"] == field and "must be in" in problem["message"]


def test_path_parameters_are_named_as_themselves():
    """A bad format or scene id in the URL is 'format' / 'scene_id', as an unknown scene's 404
    names it (was 'path.format')."""
    r = client.get("/api/v1/export/scenes/simple_pendulum/trajectory.xml")
    assert one_problem(r, 422)["field"] == "format"
    r = client.get("/api/v1/export/scenes/Simple_Pendulum/spec.toml")
    assert one_problem(r, 422)["field"] == "scene_id"


# --- found by playing the hostile user: /check with answers right on part of the range -------


@pytest.mark.parametrize(
    "quantity, answer",
    [
        # equal to ½ m l² θ̇² only where cos θ > 0 (resp. θ > 0): the judging states keep θ in
        # [0.2, 1.3], and these were 'Correct.' though wrong at the pendulum's own θ = 2
        ("T", "1/2 m l^2 theta_dot^2 * abs(cos(theta))/cos(theta)"),
        ("T", "1/2 m l^2 theta_dot^2 * sign(theta)"),
        ("V", "-m g l abs(cos(theta))"),
        ("V", "m g l (1 - abs(cos(theta)))"),  # was 'correct up to a constant'
    ],
)
def test_an_answer_right_on_only_part_of_the_range_is_not_called_correct(quantity, answer):
    r = check(answer, quantity)
    assert r.status_code == 200, r.text
    body = r.json()
    assert body["correct"] is False
    assert "part of the range" in " ".join(body["feedback"])


@pytest.mark.parametrize(
    "quantity, answer",
    [
        ("T", "1/2 m l^2 sqrt(theta_dot^4)"),  # θ̇⁴ ≥ 0: right everywhere
        ("V", "-m g l cos(abs(theta))"),  # cos is even
        ("V", "-m g l cos(theta) + 5*m*g*l"),  # a datum (an energy: a bare 5 is not one)
    ],
)
def test_answers_right_everywhere_stay_correct(quantity, answer):
    r = check(answer, quantity)
    assert r.status_code == 200 and r.json()["correct"] is True, r.text


def test_a_per_coordinate_check_without_its_coordinate_says_what_is_missing():
    body = {"scene_id": "double_pendulum", "quantity": "Q", "answer": "0"}
    problem = one_problem(client.post("/api/v1/check", json=body), 422)
    assert problem["field"] == "coordinate"
    assert "missing" in problem["message"] and "theta1, theta2" in problem["message"]


def test_a_prediction_refuses_what_simulate_refuses():
    """A negative spring constant, a radius ≤ 0: /simulate said no, /check/predict integrated
    them (the derivation took k as a magnitude and r > 0, r = √r²)."""
    cases = [
        ("spring_mass_damper", {"parameters": {"k": -1.0}}, "parameters.k", "≥ 0"),
        ("central_force", {"initial": {"r": -1.0}}, "initial.r", "> 0"),
    ]
    for scene_id, fields, field, says in cases:
        body = {"scene_id": scene_id, "quantity": "V", "answer": "0", **fields}
        problem = one_problem(client.post("/api/v1/check/predict", json=body), 422)
        assert problem["field"] == field and says in problem["message"]
        simulated = client.post("/api/v1/simulate", json={"scene_id": scene_id, **fields})
        assert field in {p["field"] for p in simulated.json()["detail"]}


@pytest.mark.parametrize(
    "answer, says, at",
    [
        # the student typed '^'; the message named the '**' it is rewritten to
        ("+^", "'^' needs a term before it", 1),
        ("theta'^", "a term is missing after '^'", 7),
        # sin(^θ̇) read as sin(**θ̇), keyword arguments: 'sin() takes no keyword arguments'
        ("sin(^theta_dot)", "'^' needs a term before it", 4),
        ("sin(*theta)", "'*' needs a term before it", 4),
    ],
)
def test_a_misplaced_power_is_named_as_typed(answer, says, at):
    problem = one_problem(check(answer), 422)
    assert problem["field"] == "answer"
    assert says in problem["message"] and "keyword" not in problem["message"]
    assert f"at character {at + 1}:" in problem["message"]


def eom(answer: str, scene_id: str = "simple_pendulum", coordinate: str = "theta"):
    body = {"scene_id": scene_id, "quantity": "eom", "coordinate": coordinate, "answer": answer}
    return client.post("/api/v1/check", json=body)


def test_an_equation_of_motion_right_on_part_of_the_range_is_not_correct():
    """θ̈ + g/l |sin θ| = 0 was 'Correct: a non-zero multiple' (sin θ > 0 where it is judged)."""
    body = eom("theta'' + g/l abs(sin(theta)) = 0").json()
    assert body["correct"] is False
    assert "part of the range" in body["feedback"][0]


@pytest.mark.parametrize("factor", ["cos(theta)", "abs(cos(theta))", "theta_dot"])
def test_an_equation_times_a_state_dependent_factor_is_named_so(factor):
    """(θ̈ + g/l sin θ)·cos θ = 0 holds along the motion; it was said to 'mix in the equations
    of the other coordinates', of a scene that has one coordinate."""
    body = eom(f"(theta'' + g/l sin(theta))*{factor} = 0").json()
    assert body["correct"] is False
    (line,) = body["feedback"]
    assert "changes with the state" in line and "other coordinates" not in line


def test_a_mix_of_two_coordinates_equations_is_still_called_a_mix():
    """The double pendulum's θ₁ equation plus its θ₂ equation: a mix, not a multiple."""
    from mechanics.check import expected_quantity
    from mechanics.expr import to_plain
    from mechanics.jobs import derivation_of

    d = derivation_of("double_pendulum", None)
    mixed = expected_quantity(d, "eom", 0) + expected_quantity(d, "eom", 1)
    body = eom(f"{to_plain(mixed)} = 0", "double_pendulum", "theta1").json()
    assert body["correct"] is False
    assert "other coordinates" in " ".join(body["feedback"])


def test_units_of_a_quantity_whose_derived_value_is_zero_are_the_quantitys():
    """The pendulum's Q_θ is 0 (gravity is in V): −m g l sin θ, a torque, was told it 'has units
    kg·m²/s², not dimensionless: it cannot belong here'. A Q_θ of an angle is a torque (N·m =
    kg·m²/s²); a mass is not."""
    body = {"scene_id": "simple_pendulum", "quantity": "Q", "coordinate": "theta"}
    torque = client.post("/api/v1/check", json={**body, "answer": "-m g l sin(theta)"}).json()
    assert not any("units" in line for line in torque["feedback"]), torque["feedback"]
    mass = client.post("/api/v1/check", json={**body, "answer": "m"}).json()
    assert any("units kg, not kg·m²/s²" in line for line in mass["feedback"]), mass["feedback"]


def test_a_lagrangian_with_abs_of_a_velocity_is_predicted_not_a_500():
    """L = ½|θ̇|³ + …: Lagrange's equations hold DiracDelta(θ̇) (d/dθ̇ of sign θ̇), which the
    integrator's math module does not know: a NameError, a 500. It is 0 away from θ̇ = 0."""
    body = {"scene_id": "simple_pendulum", "quantity": "T", "t_end": 1}
    body["answer"] = "1/2 m l^2 theta_dot^2 abs(theta_dot)"
    # |θ̇|³ has no inertia at θ̇ = 0: refused as an answer that cannot start there
    problem = one_problem(client.post("/api/v1/check/predict", json=body), 422)
    assert problem["field"] == "answer" and "no motion from the initial state" in problem["message"]
    # started moving, it runs: m l² |θ̇| θ̈ ... is a motion to draw
    r = client.post("/api/v1/check/predict", json={**body, "initial": {"theta_dot": 1.0}})
    assert r.status_code == 200, r.text
    assert r.json()["student"]["reached"] > 0


def test_a_fractional_power_of_a_negative_velocity_stops_the_run_not_the_server():
    """x_dot**0.25 at x_dot < 0 is complex in Python's arithmetic: float() of it raised a
    TypeError, a 500. The run stops there, saying it left the function's domain."""
    body = {"scene_id": "cart_pendulum", "quantity": "Q", "coordinate": "theta", "t_end": 2}
    r = client.post("/api/v1/check/predict", json={**body, "answer": "x_dot**0.25"})
    assert r.status_code == 200, r.text
    student = r.json()["student"]
    assert student["blew_up_at"] is not None and "domain" in student["stopped_because"]


def test_a_tiny_wrong_term_is_not_correct_within_a_tolerance_of_one():
    """The pendulum's Q_θ is 0; 1e-10·cos θ was 'Correct' (|difference| under 1e-9 with a floor
    of 1), and 'You mixed up θ and θ̇' (1e-10·cos θ̇ is as near 0). In SI units whole terms are
    that small (G = 6.7e-11)."""
    body = {"scene_id": "simple_pendulum", "quantity": "Q", "coordinate": "theta"}
    answer = client.post("/api/v1/check", json={**body, "answer": "1e-10*cos(theta)"}).json()
    assert answer["correct"] is False
    assert not any("mixed up" in line for line in answer["feedback"]), answer["feedback"]
    assert any("Extra term" in line for line in answer["feedback"])


def test_a_factor_that_rounds_to_one_is_not_called_a_factor_of_one():
    answer = check("1/2 m l^2 theta_dot^2 * (1 + 1e-12)").json()
    assert answer["correct"] is False
    assert not any("factor of $1$" in line for line in answer["feedback"]), answer["feedback"]
    assert "almost, but not exactly" in answer["feedback"][0]


@pytest.mark.parametrize(
    "state, field",
    [
        ({"scene_id": "simple_pendulum", "scene": {"title": "x"}}, "token.scene"),
        ({}, "token.scene_id"),
    ],
)
def test_a_token_with_both_or_neither_scene_names_which(state, field):
    """Both scene_id and scene, or neither: the error was on 'token' alone."""
    if "scene" in state:
        state = {**state, "scene": load_scene("simple_pendulum")}
    problem = one_problem(client.get(f"/s/{token_of(state)}", follow_redirects=False), 422)
    assert problem["field"] == field and "scene" in problem["message"]


def test_if_none_match_star_is_a_304_for_a_live_module():
    r = client.get("/api/v1/scenes/simple_pendulum/live.js", headers={"if-none-match": "*"})
    assert r.status_code == 304 and r.headers["etag"]


def test_the_parser_can_refuse_kinks_of_a_coordinate_where_it_is_differentiated():
    """abs() or sign() of a coordinate in a posted position is a 500 on every route (its time
    derivative stays unevaluated and cannot take numbers); parse(..., smooth=True) refuses it
    naming the field, for mechanics/model.py to use on positions and angles. A force keeps
    them (friction's sign(ṡ)), and so does an answer."""
    import sympy as sp

    from mechanics.expr import ExprError, parse

    t = sp.Symbol("t")
    names = {"theta": sp.Function("theta")(t), "l": sp.Symbol("l")}
    for text in ("l*abs(sin(theta))", "l*sign(theta)"):
        with pytest.raises(ExprError) as info:
            parse(text, names, field="bodies[0].position[0]", smooth=True)
        assert info.value.field == "bodies[0].position[0]"
        assert "no derivative" in info.value.message and info.value.position is not None
        assert parse(text, names, field="forces[0]").has(sp.Abs, sp.sign)
    assert parse("abs(l)*sin(theta)", names, smooth=True) == abs(names["l"]) * sp.sin(
        names["theta"]
    )


def test_an_answer_under_the_limit_as_typed_is_not_refused_as_too_long():
    """1,600 typed characters were refused as 'longer than 2000 characters (2481)': the count
    of the rewritten text, spaced between its tokens, not of what the student typed."""
    terms = " + ".join(f"sin(theta+{k})^2+cos(theta+{k})^2-1" for k in range(1, 45))
    answer = f"1/2 m l^2 theta_dot^2 + {terms}"
    assert len(answer) < 2000
    r = check(answer)
    assert r.status_code in (200, 503), r.text  # judged (or past the check's time budget)
    greek = "θ" * 1999  # θ θ θ … rewritten as theta * theta * …: 8 characters per θ
    problem = one_problem(check(greek), 422)
    assert "longer than" not in problem["message"]
    too_long = one_problem(check("m+" * 1000 + "m"), 422)  # 2001 typed: the schema's limit
    assert too_long["field"] == "answer" and "2000 characters" in too_long["message"]


@pytest.mark.parametrize(
    ("where", "text"),
    [
        (("bodies", 0, "position", 0), "l*abs(sin(theta))"),
        (("bodies", 0, "position", 1), "-l*sign(cos(theta))"),
    ],
)
def test_a_kinked_function_of_a_coordinate_in_a_position_is_refused_on_every_route(where, text):
    """Differentiated in time, abs(sin θ) leaves an unevaluated derivative that failed every
    later step (a 500 on derive, simulate and equilibria): refused with its field instead."""
    spec = client.get("/api/v1/scenes/simple_pendulum").json()["spec"]
    bodies, i, key, j = where
    spec[bodies][i][key][j] = text
    for route in ("derive", "simulate", "equilibria"):
        r = client.post(f"/api/v1/{route}", json={"scene": spec})
        assert r.status_code == 422, (route, r.text)
        (error,) = r.json()["detail"]
        assert error["field"] == f"bodies[0].position[{j}]"
        assert "abs()" in error["message"] or "sign()" in error["message"]


def test_friction_may_still_hold_the_sign_of_a_velocity():
    r = client.post("/api/v1/derive", json={"scene_id": "incline_friction"})
    assert r.status_code == 200
    spec = client.get("/api/v1/scenes/incline_friction").json()["spec"]
    assert "sign(" in json.dumps(spec)  # the point of the test: a force with sign(s_dot)
    assert client.post("/api/v1/derive", json={"scene": spec}).status_code == 200


def _pendulum_with_x(text: str) -> dict:
    spec = client.get("/api/v1/scenes/simple_pendulum").json()["spec"]
    spec["bodies"][0]["position"][0] = text
    return spec


def test_a_run_whose_state_leaves_a_positions_domain_stops_and_says_so():
    """x = l θ^(1/3): once θ < 0 the right-hand side is complex. It was a 500 (the finiteness
    check took a complex sum) or, cast to real by the solver, a silently wrong motion."""
    body = {"scene": _pendulum_with_x("l*theta**(1/3)"), "t_end": 3, "initial": {"theta": 0.3}}
    r = client.post("/api/v1/simulate", json=body)
    assert r.status_code == 200, r.text
    run = r.json()
    assert run["stats"]["status"] != "ok"
    assert any("left the domain" in w for w in run["warnings"])
    assert all(x >= 0 for x in run["q"]["theta"][:-1])  # never drawn past the domain's end


@pytest.mark.parametrize("text", ["l*theta**(1/3)", "l*sqrt(theta)", "l*log(theta)"])
def test_equilibria_outside_a_positions_domain_are_left_out_with_a_reason(text):
    """V = −m g l cos θ balances at θ = kπ for every k, but x = l√θ (or ∛θ, log θ) has no
    state at θ < 0, and at θ = 0 its M is infinite: those points were a 500 or a 422 about
    'units' (the complex M), or listed for a log at negative θ."""
    r = client.post("/api/v1/equilibria", json={"scene": _pendulum_with_x(text)})
    assert r.status_code == 200, r.text
    out = r.json()
    angles = [e["q"]["theta"] for e in out["equilibria"]]
    assert angles and all(a > 0 for a in angles)
    assert any(abs(a - math.pi) < 1e-9 for a in angles)  # still there: x is defined at π
    at_pi = next(e for e in out["equilibria"] if abs(e["q"]["theta"] - math.pi) < 1e-9)
    assert at_pi["kind"] == "unstable"  # V'' = m g l cos θ = −m g l < 0 at the top
    assert any("left out" in w for w in out["warnings"])


def test_a_run_whose_samples_end_before_t_end_says_so():
    """Samples lie on a grid of 1/fps from 0: t_end = 0.01 s at 60 fps answered t = [0] as an
    'ok' run, with no word that the state at t_end is missing."""
    r = client.post(
        "/api/v1/simulate", json={"scene_id": "simple_pendulum", "t_end": 0.01, "fps": 60}
    )
    assert r.status_code == 200
    run = r.json()
    assert run["t"] == [0.0]
    assert any("short of t_end" in w for w in run["warnings"])
    on_grid = client.post(
        "/api/v1/simulate", json={"scene_id": "simple_pendulum", "t_end": 7, "fps": 60}
    ).json()
    assert on_grid["t"][-1] == 7 and not any("short of" in w for w in on_grid["warnings"])


def test_a_double_equals_in_an_equation_of_motion_is_named_as_such():
    body = {
        "scene_id": "simple_pendulum",
        "quantity": "eom",
        "coordinate": "theta",
        "answer": "theta_ddot + (g/l)*sin(theta) == 0",
    }
    r = client.post("/api/v1/check", json=body)
    assert r.status_code == 422
    (error,) = r.json()["detail"]
    assert error["field"] == "answer" and "not '=='" in error["message"]
    assert "belongs only" not in error["message"]
