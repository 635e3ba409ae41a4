#!/usr/bin/env bash
# The tests: the Rust crate's (`cargo test --release`), then the Python package built and
# installed into a virtual environment (target/venv, with pytest and Ray) and its pytest
# suite. Arguments go to `cargo test`.
set -euo pipefail
cd "$(dirname "$0")/.."
# The test harness already runs two tests at a time: each plan gets one thread (unless a test
# says otherwise), which takes a tenth off the run's time and CPU.
DLO_THREADS="${DLO_THREADS:-1}" cargo test --release --locked "$@"
venv=target/venv
[ -x "$venv/bin/python" ] || python3 -m venv "$venv"
# No bytecode compiled ahead for Ray's thousands of modules (Python compiles those it imports):
# a third less CPU for the install.
"$venv/bin/python" -m pip install --quiet --no-compile --upgrade "./python[test,ray]"
"$venv/bin/python" -m pytest -q python/tests
