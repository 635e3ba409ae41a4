"""The Ray example gives the serial loop's numbers, bit for bit."""

import importlib.util

from conftest import ROOT


def load_example():
    spec = importlib.util.spec_from_file_location("ray_sweep", ROOT / "python" / "examples" / "ray_sweep.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_ray_sweep_equals_the_serial_loop():
    sweep = load_example()
    params = sweep.parameters(40)
    assert len(set(params)) == 40
    reference = sweep.serial(params)
    ray = sweep.start_ray(workers=2, address=None)
    try:
        rows = sweep.on_ray(params, batches=8)
        on_actors = sweep.on_ray(params, batches=2, workers=sweep.solvers(2))
    finally:
        ray.shutdown()
    assert rows == reference and on_actors == reference
    assert all(status == "converged" for *_, status in rows)
    # Sanity against Euler's load: a pinned rod buckles at π² Rf / L²; the elastica needs more.
    for (ratio, length), (force, *_rest) in zip(params, rows):
        assert abs(force) > 9.8696 / length**2
