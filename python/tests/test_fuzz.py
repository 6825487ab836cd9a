"""Property tests (hypothesis): mutated example files and hostile overrides never make a Rust
panic reach Python. Every call either succeeds or raises one of the documented exceptions —
ScenarioError for a refused scenario, ComputationError for a numerical failure, TypeError for
an override value of the wrong Python type — never InternalError (a caught panic) nor pyo3's
PanicException (which derives from BaseException, so it is not caught below and fails the
test).

The idea of tests/suite/mutations.rs (the library's property test) from Python: whole lines
deleted, duplicated, swapped or inserted, values replaced by extreme numbers or other types,
single characters changed. Bounded and deterministic for CI: a fixed number of examples,
derandomize=True (the same cases on every run), no example database.
"""

from __future__ import annotations

import pickle
import re

import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, event, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

import flexcraft as fc  # noqa: E402
from conftest import EXAMPLES  # noqa: E402

EXAMPLE_TEXTS = {p.name: p.read_text() for p in sorted(EXAMPLES.glob("*.toml"))}
DEPLOYMENT_EXAMPLES = sorted(n for n, t in EXAMPLE_TEXTS.items() if "\n[deployment]" in t)

# A mutation may ask for a large model (100 × 100 plate terms): refused by the memory check
# like the command line's --max-memory (the largest example needs about 160 MiB).
MAX_MEMORY = 192 << 20

# Numbers a number literal may become: signs, zero, extremes, subnormals, non-finite, the
# edges of integer ranges, values at validation bounds.
EXTREME_NUMBERS = [
    "0", "-0.0", "1", "-1", "2", "100", "1e3", "1e6", "0.5", "0.4999",
    "1e308", "-1e308", "1.7976931348623157e308", "2.2250738585072014e-308", "5e-324",
    "1e-300", "-1e-300", "nan", "inf", "-inf", "+inf",
    "9223372036854775807", "-9223372036854775808",
]  # fmt: skip
# Values a whole value may become: the numbers and other TOML types.
HOSTILE_VALUES = EXTREME_NUMBERS + [
    '"x"', '""', '"hub"', "true", "false", "[]", "[1.0]", "[[]]", "{}", "{ x = 1 }",
    "1979-05-27T07:32:00Z", '"' + "a" * 300 + '"',
]  # fmt: skip
# Lines a mutation may insert.
HOSTILE_LINES = [
    "[hub]", "[[beams]]", "[[plates]]", "[[masses]]", "[deployment]", "[deployment.hinge]",
    "[response]", "[export]", "format_version = 2", 'name = "x"', "x = 1", "terms = 40",
    'parent = "nosuch"', "",
]  # fmt: skip

NUMBER = re.compile(r"(?<![\w.\"])[-+]?\d[\d_]*(?:\.\d+)?(?:[eE][-+]?\d+)?")


def number_spans(line: str):
    """Spans of the number literals in a line's value (after '=', before a comment)."""
    code = line.split("#", 1)[0]
    eq = code.find("=")
    return [] if eq < 0 else [m.span() for m in NUMBER.finditer(code, eq + 1)]


# One edit: (kind, line index, pick, replacement) — indices taken modulo the sizes.
EDITS = st.one_of(
    st.tuples(st.just("delete"), st.integers(0, 10**4), st.just(0), st.just("")),
    st.tuples(st.just("duplicate"), st.integers(0, 10**4), st.just(0), st.just("")),
    st.tuples(st.just("swap"), st.integers(0, 10**4), st.integers(0, 10**4), st.just("")),
    st.tuples(st.just("insert"), st.integers(0, 10**4), st.just(0), st.sampled_from(HOSTILE_LINES)),
    st.tuples(st.just("value"), st.integers(0, 10**4), st.just(0), st.sampled_from(HOSTILE_VALUES)),
    st.tuples(st.just("number"), st.integers(0, 10**4), st.integers(0, 10**4), st.sampled_from(EXTREME_NUMBERS)),
    st.tuples(
        st.just("char"),
        st.integers(0, 10**4),
        st.integers(0, 10**4),
        # Any character a UTF-8 file can hold (no lone surrogates), controls and NUL included.
        st.characters(blacklist_categories=("Cs",)),
    ),
)  # fmt: skip


def mutate(text: str, edits) -> str:
    lines = text.split("\n")
    for kind, at, pick, new in edits:
        i = at % len(lines)
        if kind == "delete" and len(lines) > 1:
            del lines[i]
        elif kind == "duplicate":
            lines.insert(i, lines[i])
        elif kind == "swap":
            j = pick % len(lines)
            lines[i], lines[j] = lines[j], lines[i]
        elif kind == "insert":
            lines.insert(i, new)
        elif kind == "value" and "=" in lines[i]:
            lines[i] = lines[i].split("=", 1)[0] + "= " + new
        elif kind == "number":
            # The first line from i on that has a number in its value.
            for k in range(len(lines)):
                line = lines[(i + k) % len(lines)]
                spans = number_spans(line)
                if spans:
                    a, b = spans[pick % len(spans)]
                    lines[(i + k) % len(lines)] = line[:a] + new + line[b:]
                    break
        elif kind == "char" and lines[i]:
            p = pick % len(lines[i])
            lines[i] = lines[i][:p] + new + lines[i][p + 1 :]
    return "\n".join(lines)


def parse(text: str, name: str):
    """The scenario, or None when refused with a located ScenarioError."""
    try:
        return fc.Scenario.from_toml(text, name)
    except fc.ScenarioError as e:
        assert e.file == name and e.reason and str(e), e
        assert e.kind in ("syntax", "schema", "invalid"), e
        assert e.line >= 1 and e.column >= 1, f"no location: {e}"
        event(f"refused: {e.kind}")
        return None


def computed(label: str, f):
    """f(), or None when it raised a documented failure (counted as a hypothesis event)."""
    try:
        r = f()
    except (fc.ScenarioError, fc.ComputationError) as e:
        assert str(e)
        event(f"{label}: {type(e).__name__}")
        return None
    event(f"{label}: ran")
    return r


def exercise_modes(sc) -> None:
    """fc.modes, and every attribute made from its Rust result (pickling makes them all),
    to_dict and mode shapes."""
    m = computed("modes", lambda: fc.modes(sc, max_memory=MAX_MEMORY))
    if m is None:
        return
    assert len(pickle.loads(pickle.dumps(m)).to_dict()["modes"]) == len(m)
    for name in sc.beams[:1]:
        assert m.shape(name, [0.0, 0.5, 1.0]).shape == (len(m), 3, 6)
    for name in sc.plates[:1]:
        assert m.shape(name, [[0.0, 0.0], [1.0, 1.0]]).shape == (len(m), 2, 6)


FUZZ = settings(
    derandomize=True,
    database=None,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much],
)


@settings(FUZZ, max_examples=150)
@given(
    name=st.sampled_from(sorted(EXAMPLE_TEXTS)),
    edits=st.lists(EDITS, min_size=1, max_size=4),
)
def test_mutated_examples_never_panic(name, edits):
    """Every example file, mutated: parsed (or refused at a location), then fc.modes."""
    sc = parse(mutate(EXAMPLE_TEXTS[name], edits), name)
    if sc is not None:
        exercise_modes(sc)


@settings(FUZZ, max_examples=60)
@given(
    name=st.sampled_from(DEPLOYMENT_EXAMPLES),
    edits=st.lists(EDITS, min_size=1, max_size=3),
)
def test_mutated_deployments_never_panic(name, edits):
    """The examples with [deployment], mutated, then fc.deploy over the first second (the
    full runs take seconds each) and every attribute of its result."""
    sc = parse(mutate(EXAMPLE_TEXTS[name], edits), name)
    if sc is None or not sc.has_deployment:
        return
    d = computed(
        "deploy",
        lambda: fc.deploy(sc.with_values({"deployment.end_time": 1.0}), max_memory=MAX_MEMORY),
    )
    if d is None:
        return
    d2 = pickle.loads(pickle.dumps(d))
    assert d2.to_dict() == d.to_dict()
    assert len(d.columns["t [s]"]) == len(d.t)


def leaves(table: dict, prefix: str = ""):
    """(dotted path, value) for every value of a parsed TOML document, as with_values
    addresses them: table keys, array entries by 1-based position, named components by
    name (arrays and tables themselves included)."""
    for key, v in table.items():
        path = f"{prefix}{key}"
        yield path, v
        if isinstance(v, dict):
            yield from leaves(v, path + ".")
        elif isinstance(v, list):
            for i, item in enumerate(v, 1):
                segments = [str(i)]
                if isinstance(item, dict) and isinstance(item.get("name"), str):
                    segments.append(item["name"])
                for seg in segments:
                    if isinstance(item, dict):
                        yield from leaves(item, f"{path}.{seg}.")
                    else:
                        yield f"{path}.{seg}", item


# Paths that do not resolve, or resolve oddly.
BROKEN_PATHS = [
    "", ".", "hub..mass", "hub.mass.x", "beams.0.length", "beams.999.length",
    "hub.inertia.0", "hub.inertia.-1", "hub.inertia.4", "nosuch", "a" * 500,
]  # fmt: skip

# Python values an override may take: extreme numbers, other types, wrong types.
OVERRIDE_VALUES = [
    0, -1, 3, 10**30, -(10**30), 0.0, -0.0, 0.5, 1e308, -1e308, 5e-324, float("nan"),
    float("inf"), float("-inf"), True, False, "", "x", "fixed", "free", "a" * 300,
    None, [1.0], {}, (1, 2), b"1",
]  # fmt: skip
# Factors applied to a path's own number: plausible changes, which validation mostly accepts,
# so that fc.modes runs on many of the overridden scenarios.
FACTORS = [0.5, 0.9, 1.1, 2.0, 10.0, 1e3, 1e-3, -1.0]

_base: dict = {}


def base(name: str):
    """The example's scenario and its paths with their values (parsed once: composite.toml
    and export.toml take about half a second each, their term selection)."""
    if name not in _base:
        tomllib = pytest.importorskip("tomllib")  # Python ≥ 3.11
        values = dict(leaves(tomllib.loads(EXAMPLE_TEXTS[name])))
        _base[name] = (fc.Scenario.from_toml(EXAMPLE_TEXTS[name], name), values)
    return _base[name]


@settings(FUZZ, max_examples=150)
@given(data=st.data())
def test_hostile_overrides_never_panic(data):
    """with_values at the examples' own paths (and broken ones) with extreme values, values
    of the wrong type and scaled numbers: a ScenarioError, a TypeError (a value that is not a
    number, a string or a bool), or a scenario that fc.modes runs."""
    name = data.draw(st.sampled_from(sorted(EXAMPLE_TEXTS)), label="example")
    sc, current = base(name)
    paths = data.draw(
        st.lists(st.sampled_from(sorted(current) + BROKEN_PATHS), min_size=1, max_size=3),
        label="paths",
    )
    values = {}
    for path in paths:
        v = current.get(path)
        scaled = (
            [type(v)(v * f) if isinstance(v, float) else int(v * f) for f in FACTORS]
            if isinstance(v, (int, float)) and not isinstance(v, bool)
            else []
        )
        hostile = st.sampled_from(OVERRIDE_VALUES)
        values[path] = data.draw(
            st.one_of(st.sampled_from(scaled), hostile) if scaled else hostile, label=path
        )
    try:
        sc2 = sc.with_values(values)
    except fc.ScenarioError as e:
        assert e.reason and str(e)
        event("override: ScenarioError")
        return
    except TypeError as e:
        event("override: TypeError")
        assert any(
            not isinstance(v, (int, float, str)) for v in values.values()
        ), f"TypeError for values of accepted types: {e}"
        return
    exercise_modes(sc2)
