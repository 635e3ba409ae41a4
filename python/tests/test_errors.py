"""Bad input raises `InputError` naming the field; nothing is half-written."""

import json
import math

import numpy as np
import pytest

import dlo_planner as dlo
from conftest import CASES


def field_of(call) -> str:
    with pytest.raises(dlo.InputError) as err:
        call()
    assert err.value.message and err.value.field in str(err.value)
    return err.value.field


def rod():
    return dlo.Rod(length=1.0, flexural_rigidity=1.0)


def test_rod_fields():
    assert field_of(lambda: dlo.Rod(length=-1.0, flexural_rigidity=1.0)) == "length"
    assert field_of(lambda: dlo.Rod(1.0, float("nan"))) == "flexural_rigidity"
    assert field_of(lambda: dlo.Rod(1.0, 1.0, radius=0.7)) == "radius"
    assert isinstance(dlo.InputError("x"), ValueError)


def test_problem_fields():
    assert field_of(lambda: dlo.StaticProblem(rod(), basis_pairs=99)) == "basis_pairs"
    assert field_of(lambda: dlo.StaticProblem(rod(), basis="chebyshev")) == "basis"
    beyond = dlo.StaticProblem(rod()).fix_point(2.0, [0, 0, 1])
    assert field_of(lambda: beyond.solve()).startswith("constraint")
    clamp = dlo.StaticProblem(rod()).clamp(0.0, [0, 0, 0], [0.0, 1.0])
    assert field_of(lambda: clamp.solve()).startswith("constraint")
    ok = dlo.StaticProblem(rod()).clamp(0.0, [0, 0, 0], [0.0])
    assert field_of(lambda: ok.solve(initial=[0.0, 1.0])) == "initial"
    assert field_of(lambda: ok.solve(settings={"rho_initial": -1})) == "rho_initial"
    assert field_of(lambda: ok.solve(settings={"max_outter": 3})) == "max_outter"
    assert field_of(lambda: ok.solve(settings={"max_outer": "many"})) == "max_outer"
    assert field_of(lambda: ok.position(0.5, at_least={"w": 1.0})) == "at_least.w"


def test_obstacle_fields():
    assert field_of(lambda: dlo.Obstacle.ball("b", 0.0, [0, 0, 0])) == "radius"
    assert field_of(lambda: dlo.Obstacle.ball("b", 0.1, [0, float("inf"), 0])) == "position[1]"
    v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float)
    closed = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    tet = dlo.Obstacle.mesh("tet", v, closed)
    hull = dlo.Obstacle.convex_hull("hull", v)
    for p in ([0.1, 0.1, 0.1], [1.0, 1.0, 1.0], [-0.5, 0.2, 0.2]):
        assert tet.signed_distance(p)[1] == pytest.approx(hull.signed_distance(p)[1], abs=1e-12)
    assert field_of(lambda: dlo.Obstacle.convex_hull("flat", v[:3])) == "points"
    assert field_of(lambda: dlo.Obstacle.convex_hull("flat", np.vstack([v[:3], v[:3] * 2]))) == "points"
    assert field_of(lambda: dlo.Obstacle.half_space("table", [0, 0, 0])) == "normal"
    table = dlo.Obstacle.half_space("table", [2.0, 0, 0], position=[-0.3, 0, 0])
    assert table.signed_distance([0.2, 5.0, -7.0])[1] == pytest.approx(0.5, abs=1e-15)
    bar = dlo.Obstacle.capsule("bar", [0, -1, 0], [0, 1, 0], 0.1, position=[1.0, 0, 0])
    assert bar.signed_distance([1.5, 0.3, 0.0])[1] == pytest.approx(0.4, abs=1e-12)
    assert field_of(lambda: dlo.Obstacle.capsule("bar", [0, 0, 0], [0, 1, 0], -0.1)) == "radius"
    assert field_of(lambda: dlo.Obstacle.mesh("open", v, closed[:3])) == "triangles"
    assert field_of(lambda: dlo.Obstacle.mesh("inside-out", v, closed[:, ::-1])) == "triangles"
    assert field_of(lambda: dlo.Obstacle.mesh("bad index", v, closed + 1)) == "triangles"


def test_plan_fields():
    held = dlo.StaticProblem(rod()).clamp(0.0, [0, 0, 0], [0.0])
    start = dlo.End.pose([0.5, 0, 0.7], quaternion=[1, 0, 0, 0])
    goal = dlo.End.pose([-0.5, 0, 0.7], quaternion=[1, 0, 0, 0])
    assert field_of(lambda: dlo.plan(held, start, goal, settings={"path_terms": 0})) == "path_terms"
    assert field_of(lambda: dlo.plan(held, start, goal, settings={"k_sample": 5})) == "k_sample"
    assert field_of(lambda: dlo.plan(held, start, goal, settings={"time_limit": -1.0})) == "time_limit"
    assert field_of(lambda: dlo.plan(held, start, goal, max_speed=-1.0)) == "max_speed"
    assert field_of(lambda: dlo.plan(held, dlo.End.shape([0.0] * 3), goal)) == "start"
    far = dlo.End.pose([5.0, 0, 0.7], quaternion=[1, 0, 0, 0])
    assert field_of(lambda: dlo.plan(held, far, goal)) == "start"
    with pytest.raises(dlo.UnreachableError):
        dlo.plan(held, far, goal)
    assert field_of(lambda: dlo.End.pose([0, 0, 1], quaternion=[2, 0, 0, 0])) == "quaternion"
    assert field_of(lambda: dlo.End.pose([0, 0, 1], rotation=[[1, 0, 0], [0, 1, 0], [0, 0, 2]])) == "rotation"
    both = lambda: dlo.End.pose([0, 0, 1], rotation=[[1, 0, 0], [0, 1, 0], [0, 0, 1]], quaternion=[1, 0, 0, 0])  # noqa: E731
    assert field_of(both) == "rotation"
    assert field_of(lambda: dlo.End.pose([0, 0, 1], quaternion=[1, 0, 0, 0], angles=[0.0])) == "angles"
    assert field_of(lambda: dlo.End.pose([0, 0, 1], angles=[math.nan])) == "angles[0]"
    three = dlo.End.pose([0.5, 0, 0.7], angles=[0.0, 0.1, 0.0])
    assert field_of(lambda: dlo.plan(held, three, goal)) == "angles"


def test_case_fields(tmp_path):
    text = json.loads((CASES / "pinned_buckling_080.json").read_text())
    text["rod"]["length"] = -3
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(text))
    assert field_of(lambda: dlo.Case.load(bad)) == "rod.length"
    text["rod"]["length"] = 1.0
    text["rod"]["flexural_rigidity"] = [1.0, 2.0]
    bad.write_text(json.dumps(text))
    assert field_of(lambda: dlo.Case.load(bad)) == "rod.flexural_rigidity"
    text["rod"]["flexural_rigidity"] = 1.0
    text["constraints"][0]["s"] = "zero"
    bad.write_text(json.dumps(text))
    assert field_of(lambda: dlo.Case.load(bad)) == "constraints[0].s"
    with pytest.raises(dlo.InputError) as err:
        dlo.Case.parse("{ not json")
    assert err.value.field is None
    with pytest.raises(OSError):
        dlo.Case.load(tmp_path / "missing.json")
    assert field_of(lambda: dlo.Case.load(CASES / "pinned_buckling_080.json").evaluate()) == "shape"
    assert field_of(lambda: dlo.Case.load(CASES / "pinned_buckling_080.json").margin()) == "grasp"


def test_an_unreachable_case_goal(tmp_path):
    text = json.loads((CASES / "plan_paper_planar.json").read_text())
    text["plan"]["goal"] = {"x": 0.0, "z": 0.9, "theta": 0.0}  # inside the block
    inside = tmp_path / "inside.json"
    inside.write_text(json.dumps(text))
    with pytest.raises(dlo.UnreachableError) as err:
        dlo.Case.load(inside).plan(log_dir=tmp_path)
    assert err.value.field == "plan.goal" and "inside obstacle 'block'" in err.value.message
    assert sorted(p.name for p in tmp_path.iterdir()) == ["inside.json"]


def test_an_unwritable_log_leaves_nothing(tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(OSError):
        dlo.Case.load(CASES / "pinned_buckling_080.json").solve(log_dir=blocker / "logs")
    assert list(tmp_path.iterdir()) == [blocker]


def test_hostile_values_raise_input_errors_never_panics():
    # Random NaN, infinite, huge and negative arguments to every entry point (fixed seed):
    # each call returns a result or raises InputError (TypeError / OverflowError for values
    # Python cannot convert), never a Rust panic.
    import random

    rng = random.Random(7)
    values = [0.0, -1.0, 1e-300, 1e300, float("nan"), float("inf"), -float("inf"), 0.5, 2.0]
    v = lambda: rng.choice(values)  # noqa: E731
    few = {"max_outer": 3, "max_inner": 3}
    rods = [dlo.Rod(1.0, 1.0), dlo.Rod(1.0, 1.0, torsional_rigidity=0.8)]

    def angles(r):
        return [v() for _ in range(3 if r.spatial else 1)]

    calls = [
        lambda r: dlo.StaticProblem(r).clamp(v(), [v(), v(), v()], angles(r)).solve(settings=few),
        lambda r: dlo.StaticProblem(r).fix_point(v(), [v(), v(), v()]).solve(settings=few),
        lambda r: dlo.StaticProblem(r).load(v(), [v(), 0.0, v()], [v(), v(), v()]).solve(settings=few),
        lambda r: dlo.StaticProblem(r).obstacle(dlo.Obstacle.ball("b", 0.1, [v(), 0, v()]), v()).solve(settings=few),
        lambda r: dlo.StaticProblem(r).orientation(v(), phi=v(), theta=v()).solve(settings=few),
        lambda r: dlo.StaticProblem(r).position(v(), at_least={"x": v()}).solve(settings=few),
        lambda r: dlo.StaticProblem(r).evaluate([v()] * dlo.StaticProblem(r).coefficients),
        lambda r: dlo.StaticProblem(r).solve(settings={"rho_initial": v(), "perturbation": v()}),
        lambda r: dlo.Rod(v(), v(), torsional_rigidity=v(), weight_per_length=v(), radius=v()),
        lambda r: dlo.StaticProblem(r, base=[v(), v(), v()]).solve(settings=few, points=rng.choice([0, 1, 2])),
        lambda r: dlo.End.pose([v(), v(), v()], quaternion=[v(), v(), v(), v()]),
        lambda r: dlo.plan(
            dlo.StaticProblem(r).clamp(0.0, [0, 0, 0], [0.0] * (3 if r.spatial else 1)),
            dlo.End.shape([v()] * rng.choice([3, 10, 40])),
            dlo.End.pose([v(), 0.0, v()], quaternion=[1, 0, 0, 0]),
        ),
    ]
    for _ in range(40):
        for call in calls:
            try:
                call(rng.choice(rods))
            except (dlo.InputError, TypeError, OverflowError):
                pass
