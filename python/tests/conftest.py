"""Shared fixtures: the repository root, the command-line tool, and its outputs cached per
session (the seed's deploy and simulate take a few seconds each)."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def cli_command() -> list:
    """The built `flexcraft` binary (target/release, or $CARGO_TARGET_DIR/release), else
    `cargo run --release --`."""
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    if not target.is_absolute():
        target = ROOT / target
    for exe in (target / "release" / "flexcraft", ROOT / "target" / "release" / "flexcraft"):
        if exe.is_file():
            return [str(exe)]
    if shutil.which("cargo") is None:
        pytest.skip("neither target/release/flexcraft nor cargo is available")
    return ["cargo", "run", "--quiet", "--release", "--manifest-path", str(ROOT / "Cargo.toml"), "--"]


_cache: dict = {}


def run_cli(*args: str) -> subprocess.CompletedProcess:
    key = args
    if key not in _cache:
        _cache[key] = subprocess.run(
            cli_command() + list(args), capture_output=True, text=True, cwd=ROOT
        )
    return _cache[key]


def cli_json(command: str, scenario: Path) -> dict:
    p = run_cli(command, str(scenario), "--json")
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


@pytest.fixture(scope="session")
def seed_path() -> Path:
    return EXAMPLES / "seed.toml"


@pytest.fixture(scope="session")
def seed(seed_path):
    import flexcraft as fc

    return fc.Scenario.from_file(seed_path)


@pytest.fixture(scope="session")
def seed_simulation(seed):
    import flexcraft as fc

    return fc.simulate(seed)


@pytest.fixture(scope="session")
def seed_cli_out(tmp_path_factory, seed_path) -> Path:
    """`flexcraft simulate seed.toml --out DIR`'s folder."""
    out = tmp_path_factory.mktemp("cli") / "seed"
    p = run_cli("simulate", str(seed_path), "--out", str(out), "--quiet")
    assert p.returncode == 0, p.stderr
    return out
