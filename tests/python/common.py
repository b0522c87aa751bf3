"""Shared by the Python binding's tests: where the repository, the program and the worlds are."""

import os
import pathlib
import subprocess

ROOT = pathlib.Path(os.environ.get("SWARMSIM_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
BINARY = os.environ.get("SWARMSIM_BINARY", str(ROOT / "build" / "swarmsim"))
PYTHON = os.environ.get("SWARMSIM_PYTHON", "/usr/bin/python3")


def world(*parts):
    return str(ROOT.joinpath("worlds", *parts))


def run(args, env_extra=None, cwd=None):
    """Runs a command, returns (exit status, stdout + stderr)."""
    env = dict(os.environ)
    env.update(env_extra or {})
    p = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env,
                       cwd=cwd or ROOT, timeout=600)
    return p.returncode, p.stdout
