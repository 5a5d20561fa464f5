"""Build the Lambda code bundle (the skill, the announcer and the dispatcher): the one build
used by CDK and by the ASK CLI path.

    python -m infra.lambda_asset OUT_DIR [--architecture x86_64|arm64] [--zip FILE]

The bundle holds three functions' code roots: `skill/` (from `lambda/skill`, handler
`skill.app.lambda_handler`), `announcer/` (from `lambda/announcer`, handler
`announcer.app.lambda_handler`) and `dispatcher/` (from `lambda/dispatcher`, handler
`dispatcher.app.lambda_handler`); the parts of `vahr` they import (`vahr/__init__.py`,
`vahr/errors.py`, the wire contract `vahr/protocol`, the domain `vahr/domain`, the dispatch
core `vahr/dispatch` for the skill and the dispatcher, and `vahr/announce` for the
announcer), `fleet.yaml` as
`vahr/domain/fleet.yaml` (where `vahr.domain.fleet` looks for it) with, for a fleet on
a map, its zones' distance fields beside it (`vahr/domain/fleet-distances.bin`, written by
`infra/floor_distances.py`: the dispatcher ranks by path length without numpy), and the
runtime
dependencies installed from wheels built for the Lambda runtime (CPython 3.12 on Amazon
Linux), so no Docker is needed. boto3 comes from the Lambda runtime and awscrt must stay
out: botocore imports awscrt whenever it is present, which costs cold start.

One bundle serves every function: a cold start pays for the modules a handler imports, not
for the files it leaves alone (the announcer and the dispatcher import no ASK SDK), and one
build, one asset hash and one upload stay simpler than three.

Installed dependencies are cached under `.cache/lambda-deps/<key>`, keyed by the pins and
the target platform, so a rebuild copies files instead of running pip.
"""

from __future__ import annotations

import argparse
import ast
import hashlib
import importlib.metadata
import os
import re
import shutil
import subprocess
import sys
import tempfile
import zipfile
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from vahr.errors import VahrError

if TYPE_CHECKING:
    from collections.abc import Sequence

REPO_ROOT = Path(__file__).resolve().parent.parent
LAMBDA_PYTHON = "3.12"
# The skill's direct runtime dependencies; their versions come from requirements.txt.
RUNTIME_PACKAGES = ("ask-sdk-core", "ask-sdk-model", "msgspec", "pyyaml")
PLATFORMS = {"x86_64": "manylinux2014_x86_64", "arm64": "manylinux2014_aarch64"}
# What the Lambda Python runtime itself provides; installed only by `runtime_site`, to check
# a bundle outside Lambda the way the runtime would load it.
RUNTIME_PROVIDED = ("boto3",)
# Provided by the runtime (boto3, botocore) or harmful there (awscrt slows every boto3
# client's import; awsiot is the robots' SDK).
FORBIDDEN_TOP_LEVEL = ("awscrt", "awsiot", "boto3", "botocore", "s3transfer")
# The project files the functions need, relative to the repository root (vahr.announce
# for the announcer only, vahr.dispatch for the skill and the dispatcher).
VAHR_FILES = ("vahr/__init__.py", "vahr/errors.py")
VAHR_PACKAGES = ("vahr/protocol", "vahr/domain", "vahr/dispatch", "vahr/announce")
SKILL_DIR = "lambda/skill"
# Each function's code root: its package name in the bundle, and where it lives here.
CODE_ROOTS = {
    "skill": SKILL_DIR,
    "announcer": "lambda/announcer",
    "dispatcher": "lambda/dispatcher",
}
# Where `vahr.domain.fleet` looks for the bundled fleet definition.
FLEET_IN_BUNDLE = "vahr/domain/fleet.yaml"
# Where `vahr.dispatch.grid_routes` looks for a map fleet's distances (BUNDLED_FILE).
DISTANCES_IN_BUNDLE = "vahr/domain/fleet-distances.bin"
LOCALES_IN_BUNDLE = "vahr/domain/locales"
_IGNORED = shutil.ignore_patterns("__pycache__", "*.pyc", ".mypy_cache", ".pytest_cache")
_REQUIREMENT = re.compile(r"^\s*([A-Za-z0-9][A-Za-z0-9._-]*)\s*==\s*([^\s;#]+)")
_ZIP_TIME = (1980, 1, 1, 0, 0, 0)


@dataclass(frozen=True)
class BuildResult:
    """What was built: where, how many files, how many bytes unzipped."""

    out_dir: Path
    files: int
    size_bytes: int
    from_cache: bool


def normalize(name: str) -> str:
    """A distribution name in PEP 503 form (`PyYAML` -> `pyyaml`)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def runtime_pins(
    requirements: Path = REPO_ROOT / "requirements.txt",
    packages: Sequence[str] = RUNTIME_PACKAGES,
) -> list[str]:
    """`name==version` for each of `packages`, as pinned in requirements.txt."""
    pins: dict[str, str] = {}
    for line in requirements.read_text().splitlines():
        found = _REQUIREMENT.match(line)
        if found:
            pins[normalize(found[1])] = f"{found[1]}=={found[2]}"
    missing = [name for name in packages if normalize(name) not in pins]
    if missing:
        raise VahrError(f"{requirements}: no '==' pin for {', '.join(missing)}")
    return [pins[normalize(name)] for name in packages]


def constraints() -> list[str]:
    """The versions installed here, so the bundle's transitive dependencies match what the
    tests ran against rather than whatever is newest on PyPI today."""
    lines = set()
    for dist in importlib.metadata.distributions():
        name, version = dist.metadata["Name"], dist.version
        if name and version and "+" not in version and normalize(name) != "vahr":
            lines.add(f"{normalize(name)}=={version}")
    return sorted(lines)


def _source_files(fleet_file: Path) -> list[tuple[Path, str]]:
    """(source file, path inside the bundle) for every project file the bundle carries."""
    pairs: list[tuple[Path, str]] = []
    for package, directory in CODE_ROOTS.items():
        root = REPO_ROOT / directory
        for path in sorted(root.rglob("*")):
            if path.is_file() and "__pycache__" not in path.parts and path.suffix != ".pyc":
                pairs.append((path, f"{package}/" + path.relative_to(root).as_posix()))
    for name in VAHR_FILES:
        pairs.append((REPO_ROOT / name, name))
    for package in VAHR_PACKAGES:
        for path in sorted((REPO_ROOT / package).rglob("*.py")):
            if "__pycache__" not in path.parts:
                pairs.append((path, path.relative_to(REPO_ROOT).as_posix()))
    # Each locale's words and message catalog (vahr.domain.locale reads them).
    for path in sorted((REPO_ROOT / LOCALES_IN_BUNDLE).rglob("*.yaml")):
        pairs.append((path, path.relative_to(REPO_ROOT).as_posix()))
    pairs.append((fleet_file, FLEET_IN_BUNDLE))
    return pairs


def _dependency_key(architecture: str, packages: Sequence[str] = RUNTIME_PACKAGES) -> str:
    digest = hashlib.sha256()
    pins = runtime_pins(packages=packages)
    for part in (LAMBDA_PYTHON, PLATFORMS[architecture], *pins, *constraints()):
        digest.update(part.encode() + b"\0")
    return digest.hexdigest()[:16]


def source_hash(
    *, architecture: str = "x86_64", fleet_file: Path | None = None, precompiled: bool = False
) -> str:
    """A hash of everything that goes into the bundle, for CDK's custom asset hash."""
    digest = hashlib.sha256(_dependency_key(architecture).encode())
    digest.update(b"precompiled" if precompiled else b"source")
    for source, name in _source_files(fleet_file or REPO_ROOT / "fleet.yaml"):
        digest.update(name.encode() + b"\0")
        if source.exists():
            digest.update(source.read_bytes())
    # A map's distances change with the map: its YAML and image count too.
    for source in _map_files(fleet_file or REPO_ROOT / "fleet.yaml"):
        digest.update(source.read_bytes())
    return digest.hexdigest()


def _map_files(fleet_file: Path) -> list[Path]:
    """The map YAML and image the fleet's floor names, if any."""
    from vahr.domain import load_fleet
    from vahr.navigation.occupancy import MapFile

    try:
        floor = load_fleet(fleet_file).floor
    except ValueError:
        return []
    if floor is None or floor.map is None:
        return []
    import msgspec

    map_yaml = Path(floor.map)
    try:
        image = map_yaml.parent / msgspec.yaml.decode(map_yaml.read_bytes(), type=MapFile).image
    except (OSError, msgspec.ValidationError, msgspec.DecodeError):
        return [map_yaml] if map_yaml.is_file() else []
    return [path for path in (map_yaml, image) if path.is_file()]


def _install_dependencies(
    architecture: str, cache_root: Path, packages: Sequence[str] = RUNTIME_PACKAGES
) -> tuple[Path, bool]:
    """The directory holding the installed `packages`; True when it came from the cache."""
    key = _dependency_key(architecture, packages)
    target = cache_root / "lambda-deps" / f"{architecture}-{key}"
    if (target / ".complete").exists():
        return target, True
    target.parent.mkdir(parents=True, exist_ok=True)
    staging = Path(tempfile.mkdtemp(prefix="staging-", dir=target.parent))
    try:
        constraint_file = staging / "constraints.txt"
        constraint_file.write_text("\n".join(constraints()) + "\n")
        site = staging / "site"
        command = [
            sys.executable, "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
            "--no-input", "--no-compile", "--target", str(site),
            "--platform", PLATFORMS[architecture], "--python-version", LAMBDA_PYTHON,
            "--implementation", "cp", "--only-binary=:all:",
            "--cache-dir", str(cache_root / "pip"), "--constraint", str(constraint_file),
            *runtime_pins(packages=packages),
        ]  # fmt: skip
        try:
            subprocess.run(command, check=True, capture_output=True, text=True, timeout=600)
        except subprocess.CalledProcessError as err:
            reason = (err.stderr or err.stdout).strip().splitlines()
            raise VahrError(
                f"pip could not install the skill's dependencies: {reason[-1:]}"
            ) from err
        except subprocess.TimeoutExpired as err:
            raise VahrError("pip took more than 10 minutes to install the dependencies") from err
        # Console scripts are useless in Lambda and carry the build machine's paths.
        shutil.rmtree(site / "bin", ignore_errors=True)
        (site / ".complete").touch()
        # Another build (a parallel test, a second synth) may have finished first: keep
        # its complete copy; only a half-written one from a killed build is replaced.
        if not (target / ".complete").exists():
            shutil.rmtree(target, ignore_errors=True)
            try:
                site.rename(target)
            except OSError:
                if not (target / ".complete").exists():
                    raise
    finally:
        shutil.rmtree(staging, ignore_errors=True)
    return target, False


def _vahr_imports(code_root: Path) -> set[str]:
    """Every `vahr...` module a function's code imports (absolute imports only)."""
    modules: set[str] = set()
    for path in code_root.rglob("*.py"):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            if isinstance(node, ast.Import):
                modules.update(alias.name for alias in node.names)
            elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
                modules.add(node.module)
    return {module for module in modules if module == "vahr" or module.startswith("vahr.")}


def _check_bundle(out_dir: Path) -> None:
    for name in FORBIDDEN_TOP_LEVEL:
        if (out_dir / name).exists():
            raise VahrError(f"the Lambda bundle must not contain {name}/ (remove it from the deps)")
    for package, directory in CODE_ROOTS.items():
        if not (out_dir / package / "app.py").is_file():
            raise VahrError(
                f"{directory}/app.py is missing: the handler is {package}.app.lambda_handler"
            )
        for module in sorted(_vahr_imports(out_dir / package)):
            parts = module.split(".")
            as_package = out_dir.joinpath(*parts, "__init__.py")
            as_module = out_dir.joinpath(*parts[:-1], parts[-1] + ".py")
            if not as_package.exists() and not as_module.exists():
                raise VahrError(
                    f"the {package} imports {module}, which the bundle does not carry "
                    f"(add it to VAHR_FILES or VAHR_PACKAGES in infra/lambda_asset.py)"
                )


def _write_floor_distances(fleet_file: Path, out_dir: Path) -> None:
    """For a fleet on a map, its zones' distance fields, where the dispatcher reads them."""
    from vahr.domain import load_fleet
    from vahr.protocol import ProtocolError

    try:
        fleet = load_fleet(fleet_file)
    except ProtocolError as err:
        raise VahrError(f"fleet file {fleet_file}: {err}") from err
    if fleet.floor is None or fleet.floor.map is None:
        return
    from infra.floor_distances import write_distances

    write_distances(fleet, out_dir / DISTANCES_IN_BUNDLE)


def _tree_size(root: Path) -> tuple[int, int]:
    files = [path for path in root.rglob("*") if path.is_file()]
    return len(files), sum(path.stat().st_size for path in files)


# Where Lambda unpacks a function's code ($LAMBDA_TASK_ROOT).
LAMBDA_TASK_ROOT = "/var/task"


def precompile(bundle: Path, python: Path) -> None:
    """Write byte code for every module with `python` (a CPython 3.12).

    The Lambda runtime cannot write `__pycache__` in its read-only code directory, so
    without this every cold start compiles each imported module again (measured here:
    importing skill.app took a median 0.6 s from source and 0.25 s from byte code; see
    bench/lambda_bundle.py).
    """
    try:
        found = subprocess.run(
            [str(python), "-c", "import sys; print('%d.%d' % sys.version_info[:2])"],
            check=True, capture_output=True, text=True, timeout=30,
        ).stdout.strip()  # fmt: skip
    except (OSError, subprocess.SubprocessError) as err:
        raise VahrError(f"cannot run {python} to precompile the bundle ({err})") from err
    if found != LAMBDA_PYTHON:
        raise VahrError(f"{python} is Python {found}; byte code must come from {LAMBDA_PYTHON}")
    # unchecked-hash: the runtime uses the .pyc without comparing source timestamps, which
    # the zip upload does not keep anyway. Each module's file name is written as Lambda
    # will see it (/var/task/...), not this build's directory: the byte code (and its
    # size, held to a budget by the tests) is the same wherever the bundle is built.
    command = [str(python), "-m", "compileall", "-q", "-j", "0", "--invalidation-mode",
               "unchecked-hash", "-s", str(bundle), "-p", LAMBDA_TASK_ROOT,
               str(bundle)]  # fmt: skip
    try:
        subprocess.run(command, check=True, capture_output=True, timeout=300)
    except (OSError, subprocess.SubprocessError) as err:
        raise VahrError(f"precompiling the bundle with {python} failed ({err})") from err


def build(
    out_dir: Path,
    *,
    architecture: str = "x86_64",
    fleet_file: Path | None = None,
    cache_root: Path | None = None,
    compile_with: Path | None = None,
) -> BuildResult:
    """Write the bundle into `out_dir` (created if needed; must be empty or absent).

    With `compile_with` (a CPython 3.12 interpreter) the bundle also carries byte code.
    """
    if architecture not in PLATFORMS:
        raise VahrError(f"architecture: {architecture!r} must be one of {', '.join(PLATFORMS)}")
    fleet_file = fleet_file or REPO_ROOT / "fleet.yaml"
    if not fleet_file.is_file():
        raise VahrError(f"fleet file {fleet_file} does not exist")
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise VahrError(f"cannot make the directory {out_dir}: {err.strerror or err}") from err
    if any(out_dir.iterdir()):
        raise VahrError(f"{out_dir} is not empty: give the build an empty directory")
    deps, from_cache = _install_dependencies(architecture, cache_root or REPO_ROOT / ".cache")
    shutil.copytree(deps, out_dir, dirs_exist_ok=True, ignore=shutil.ignore_patterns(".complete"))
    for source, name in _source_files(fleet_file):
        destination = out_dir / name
        destination.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source, destination)
    _write_floor_distances(fleet_file, out_dir)
    _check_bundle(out_dir)
    if compile_with is not None:
        precompile(out_dir, compile_with)
    files, size = _tree_size(out_dir)
    return BuildResult(out_dir=out_dir, files=files, size_bytes=size, from_cache=from_cache)


def runtime_site(*, architecture: str = "x86_64", cache_root: Path | None = None) -> Path:
    """A directory holding what the Lambda runtime provides (boto3 at the pinned version),
    to put on `sys.path` after a bundle when checking it outside Lambda."""
    site, _ = _install_dependencies(
        architecture, cache_root or REPO_ROOT / ".cache", packages=RUNTIME_PROVIDED
    )
    return site


def write_zip(bundle: Path, zip_file: Path) -> None:
    """Zip `bundle` reproducibly (sorted names, fixed times) for uploads outside CDK."""
    zip_file.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(zip_file, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for path in sorted(p for p in bundle.rglob("*") if p.is_file()):
            info = zipfile.ZipInfo(path.relative_to(bundle).as_posix(), date_time=_ZIP_TIME)
            info.external_attr = 0o644 << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, path.read_bytes())


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m infra.lambda_asset", description=__doc__.split("\n\n")[0]
    )
    parser.add_argument("out_dir", type=Path, help="empty or new directory for the bundle")
    parser.add_argument("--architecture", choices=sorted(PLATFORMS), default="x86_64")
    parser.add_argument("--fleet-file", type=Path, help="fleet definition (default fleet.yaml)")
    parser.add_argument("--zip", type=Path, dest="zip_file", help="also write the bundle as a zip")
    parser.add_argument(
        "--compile-with",
        type=Path,
        metavar="PYTHON3.12",
        help="precompile the bundle with this CPython 3.12 (faster cold starts, ~5 MB more)",
    )
    args = parser.parse_args(argv)
    try:
        result = build(
            args.out_dir,
            architecture=args.architecture,
            fleet_file=args.fleet_file,
            compile_with=args.compile_with,
        )
        if args.zip_file is not None:
            write_zip(result.out_dir, args.zip_file)
    except VahrError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(
        f"{result.out_dir}: {result.files} files, {result.size_bytes / 1e6:.1f} MB unzipped"
        f"{' (dependencies from cache)' if result.from_cache else ''}"
    )
    return 0


if __name__ == "__main__":
    os.environ.setdefault("PIP_DISABLE_PIP_VERSION_CHECK", "1")
    sys.exit(main())
