"""Static shapes from Python against the CLI and closed forms."""

import math

import numpy as np
import pytest

import dlo_planner as dlo
from conftest import CASES, cli_json


def pinned_elastica() -> dlo.StaticProblem:
    """`planning_cases/pinned_buckling_080.json` built in code: L = 100, Rf = 1, both ends
    pinned 0.80 L apart, in the paper's basis as the case names it."""
    rod = dlo.Rod(length=100.0, flexural_rigidity=1.0, radius=0.05)
    return dlo.StaticProblem(rod, basis="paper").position(100.0, name="right pin", equal={"x": 0.0, "z": 80.0})


def test_pinned_elastica_force_equals_the_cli(dlo_bin, tmp_path):
    cli = cli_json(dlo_bin, "shape", str(CASES / "pinned_buckling_080.json"), "--log-dir", str(tmp_path))
    shape = pinned_elastica().solve(name="pinned_buckling_080")
    assert shape.converged
    pin = [r for r in shape.reactions if r.constraint == "right pin"][0]
    cli_pin = [r for r in cli["reactions"] if r["constraint"] == "right pin"][0]
    np.testing.assert_allclose(pin.force, cli_pin["force"], rtol=0, atol=1e-12)
    assert abs(shape.energy.total - cli["energy"]["total"]) <= 1e-12
    # The same case read from its file gives the CLI's whole report, timing aside.
    from_case = dlo.Case.load(CASES / "pinned_buckling_080.json").solve().to_dict()
    for r in (from_case, cli):
        r.pop("timing_s")
        r.pop("mcap", None)
    assert from_case == cli


def test_pinned_elastica_force_against_the_elliptic_integral():
    # The pinned–pinned elastica with end shortening: 1 − l/L = 2(1 − E(k)/K(k)) and
    # F L²/Rf = 4 K(k)², with k = sin(α/2). Bisection on k gives the closed form.
    def ellip(k):
        # Complete elliptic integrals K and E by the arithmetic–geometric mean.
        a, b, c, p = 1.0, math.sqrt(1 - k * k), k, 1.0
        e_sum = 0.5 * c * c
        for _ in range(40):  # quadratic convergence: far more than enough
            a, b, c = (a + b) / 2, math.sqrt(a * b), (a - b) / 2
            p *= 2
            e_sum += 0.5 * p * c * c
        K = math.pi / (2 * a)
        return K, K * (1 - e_sum)

    lo, hi = 1e-6, 1 - 1e-12
    for _ in range(200):
        mid = (lo + hi) / 2
        K, E = ellip(mid)
        if 2 * E / K - 1 > 0.80:
            lo = mid
        else:
            hi = mid
    K, _ = ellip(lo)
    force = 4 * K * K / 100.0**2
    shape = pinned_elastica().solve(settings={"optimality_tol": 1e-10})
    pin = [r for r in shape.reactions if r.constraint == "right pin"][0]
    # The paper's basis (4 pairs) is within 2e-3 of the closed form here (docs/validation.md).
    assert abs(abs(pin.force[2]) - force) / force < 2e-3


def test_shape_arrays_match_the_report():
    shape = pinned_elastica().solve(points=11, report_points=[50.0])
    assert shape.s.shape == (11,) and shape.positions.shape == (11, 3)
    assert shape.frames.shape == (11, 3, 3)
    np.testing.assert_allclose(shape.positions[-1], shape.end_pose.position, atol=1e-12)
    np.testing.assert_allclose(shape.positions[5], shape.points[0].position, atol=1e-12)
    np.testing.assert_allclose(shape.positions[-1], [0.0, 0.0, 80.0], atol=1e-6)
    for r in shape.frames:
        np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-12)
    # Evaluating the solved coefficients reproduces the energy.
    ev = pinned_elastica().evaluate(shape.a)
    assert ev.status == "evaluated" and abs(ev.energy.total - shape.energy.total) < 1e-14


def test_a_cable_sags_onto_a_ball():
    # examples/library.rs from Python: a 3D cable clamped at both ends along +y, sagging
    # onto a ball (gravity along −x).
    rod = dlo.Rod(0.5, 0.01, torsional_rigidity=0.008, weight_per_length=0.3, radius=0.004)
    ball = dlo.Obstacle.ball("ball", 0.05, position=[-0.16, 0.2, 0.0])
    along_y = [math.pi / 2, math.pi / 2, 0.0]
    problem = (
        dlo.StaticProblem(rod, basis_pairs=6)
        .clamp(0.0, [0, 0, 0], along_y)
        .clamp(0.5, [0.0, 0.4, 0.0], along_y)
        .obstacle(ball)
    )
    shape = problem.solve()
    assert shape.converged
    gap = min(ball.signed_distance(list(p))[1] for p in shape.positions) - rod.radius
    assert gap > -1e-6
    ball_force = [r for r in shape.reactions if "ball" in r.constraint]
    assert ball_force and ball_force[0].force[0] > 1e-3
    # The reactions carry the weight w L = 0.15 N (x is up).
    lift = sum(r.force[0] for r in shape.reactions)
    assert abs(lift - 0.3 * 0.5) < 1e-6


def test_a_grasp_built_in_code_equals_the_case():
    # planning_cases/grasp_a_080.json in code (the paper's basis, as the case names it):
    # fingers are positions with one bound.
    rod = dlo.Rod(length=100.0, flexural_rigidity=1.0, radius=0.05)
    grasp = (
        dlo.StaticProblem(rod, basis="paper", free_base=True)
        .position(0.0, name="left finger", equal={"x": 0.0}, at_least={"z": 0.0})
        .position(100.0, name="right finger", equal={"x": 0.0}, at_most={"z": 80.0})
    )
    case = dlo.Case.load(CASES / "grasp_a_080.json")
    ours = dlo.grasp_margin(grasp, settings=dict(case_grasp_section()), name=case.name)
    theirs = case.margin()
    np.testing.assert_array_equal(ours.f_mub, theirs.f_mub)
    np.testing.assert_array_equal(ours.mu, theirs.mu)


def case_grasp_section() -> dict:
    import json

    return json.loads((CASES / "grasp_a_080.json").read_text()).get("grasp", {})


def test_a_grasp_margin_from_code_equals_the_case(dlo_bin, tmp_path):
    case = dlo.Case.load(CASES / "grasp_a_080.json")
    cli = cli_json(dlo_bin, "margin", str(CASES / "grasp_a_080.json"), "--log-dir", str(tmp_path))
    margin = case.margin().to_dict()
    for r in (margin, cli):
        r.pop("timing_s")
        r.pop("mcap", None)
    assert margin == cli


@pytest.mark.parametrize("case", ["clamped_buckling_060", "self_contact_crossed_loop"])
def test_case_reports_equal_the_cli(dlo_bin, tmp_path, case):
    cli = cli_json(dlo_bin, "shape", str(CASES / f"{case}.json"), "--log-dir", str(tmp_path))
    ours = dlo.Case.load(CASES / f"{case}.json").solve().to_dict()
    for r in (ours, cli):
        r.pop("timing_s")
        r.pop("mcap", None)
    assert ours == cli


def test_results_pickle_for_process_pools():
    import pickle

    shape = pinned_elastica().solve()
    back = pickle.loads(pickle.dumps(shape))
    assert back == shape and back.energy.total == shape.energy.total
    np.testing.assert_array_equal(back.positions, shape.positions)


@pytest.mark.parametrize("case,command", [("pinned_buckling_080", "shape"), ("grasp_a_080", "margin")])
def test_logs_hold_what_the_cli_logs(dlo_bin, tmp_path, log_dir, case, command):
    cli_json(dlo_bin, command, str(CASES / f"{case}.json"), "--log-dir", str(tmp_path))
    loaded = dlo.Case.load(CASES / f"{case}.json")
    result = loaded.solve(log_dir=log_dir) if command == "shape" else loaded.margin(log_dir=log_dir)
    assert result.mcap == str(log_dir / f"{case}.mcap")

    def topics(path):
        found = cli_json(dlo_bin, "inspect", str(path))["topics"]
        return {t: (v["schema"], v["encoding"], v["messages"]) for t, v in found.items()}

    assert topics(log_dir / f"{case}.mcap") == topics(tmp_path / f"{case}.mcap")
    assert not [p for p in log_dir.iterdir() if p.name.endswith(".partial")]


def _solve_ratio(ratio: float) -> float:
    shape = pinned_elastica_at(ratio).solve()
    return [r for r in shape.reactions if r.constraint == "right pin"][0].force[2]


def pinned_elastica_at(ratio: float) -> dlo.StaticProblem:
    rod = dlo.Rod(length=100.0, flexural_rigidity=1.0, radius=0.05)
    return dlo.StaticProblem(rod).position(100.0, name="right pin", equal={"x": 0.0, "z": 100.0 * ratio})


def test_a_process_pool_gives_the_serial_numbers():
    from concurrent.futures import ProcessPoolExecutor

    ratios = [0.5, 0.6, 0.7, 0.8]
    with ProcessPoolExecutor(max_workers=2) as pool:
        pooled = list(pool.map(_solve_ratio, ratios))
    assert pooled == [_solve_ratio(r) for r in ratios]


def test_evaluate_equals_dlo_energy(dlo_bin):
    cli = cli_json(dlo_bin, "energy", str(CASES / "topology_one_knot_020.json"))
    ours = dlo.Case.load(CASES / "topology_one_knot_020.json").evaluate().to_dict()
    for r in (ours, cli):
        r.pop("timing_s")
    assert ours == cli


def test_margin_progress_reaches_every_limit():
    seen = []
    margin = dlo.Case.load(CASES / "grasp_a_080.json").margin(progress=lambda e, info: seen.append((e, info)))
    assert seen and all(e == "margin" for e, _ in seen)
    assert seen[-1][1]["done"] == seen[-1][1]["total"] == len(margin.table)


def test_chord_contacts_keep_a_strip_on_a_corner_out_of_the_block():
    # The paper's planar strip clamped along +z under the block z >= 0.8, |x| <= 0.2
    # (planning_cases/plan_paper_planar.json's static problem): at its sample points it keeps
    # the radius while its polyline cuts the corner; on chords the polyline keeps it.
    rod = dlo.Rod(length=1.0, flexural_rigidity=1.0, radius=0.005)
    block = dlo.Obstacle.cuboid("block", [0.2, 0.5, 0.5], position=[0.0, 0.0, 1.3])

    def polyline_gap(contact):
        problem = dlo.StaticProblem(rod, contact=contact).orientation(0.0, theta=0.0)
        shape = problem.obstacle(block).solve()
        assert shape.converged
        x = np.asarray(shape.positions)
        pts = [a + t * (b - a) for a, b in zip(x[:-1], x[1:]) for t in np.linspace(0.0, 1.0, 21)]
        return min(block.signed_distance(list(p))[1] for p in pts) - rod.radius, shape

    points_gap, points = polyline_gap("points")
    chords_gap, chords = polyline_gap("chords")
    assert points_gap < -4e-3
    assert -1e-9 <= chords_gap <= 1e-4
    assert chords.energy.total > points.energy.total
    with pytest.raises(dlo.InputError) as e:
        dlo.StaticProblem(rod, contact="edges")
    assert e.value.field == "contact"
