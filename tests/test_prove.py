"""``ptoverify prove``: the proofs against simulation, faulty configurations, certificates.

The reference for the reach bound is the simulator (``simulate_batch``, exact
ZOH flow): from seeded states the simulated number of samples to enter the
same ellipse must never exceed the certified bound of the cell holding the
state.  Faulty configurations must not prove.  The independent checker must
accept the certificates and reject tampered ones.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest
from conftest import cell_states

from ptoverify.cli import main
from ptoverify.config import paper_config
from ptoverify.model.laws import make_law
from ptoverify.sim.simulate import simulate_batch
from ptoverify.studies.prove import nominal_proof, parse_a_interval
from ptoverify.studies.prove.ball import Resolution
from ptoverify.studies.prove.certificate import certificate_arrays, check_certificate
from ptoverify.studies.prove.run import prove_law


@pytest.fixture(scope="module")
def pd_proof():
    return prove_law(paper_config(), "pd", n_random=1000)


def _first_inside(proof, b) -> np.ndarray:
    """First sample of each simulated trajectory inside the proof's ellipse (inf: never)."""
    (p11, p12), (_, p22) = proof.target.P
    q = p11 * b.x1**2 + 2 * p12 * b.x1 * b.x2 + p22 * b.x2**2
    inside = q <= proof.target.c * (1 + 1e-9)
    return np.where(inside.any(axis=0), inside.argmax(axis=0), np.inf)


def _cell_bound(proof, x1, x2) -> np.ndarray:
    g = proof.grid
    i = np.clip(np.searchsorted(g.e1, x1, "right") - 1, 0, g.shape[0] - 1)
    j = np.clip(np.searchsorted(g.e2, x2, "right") - 1, 0, g.shape[1] - 1)
    return proof.bound[j * g.shape[0] + i]


def _bound_vs_simulation(proof, n: int, seed: int, chunk: int = 50_000) -> tuple[int, int]:
    cfg = paper_config()
    law = make_law(proof.law, cfg)
    rng = np.random.default_rng(seed)
    over = worst = 0
    steps = int(proof.bound_samples) + 2
    for at in range(0, n, chunk):
        m = min(chunk, n - at)
        x1 = rng.uniform(-cfg.plant.position_range, cfg.plant.position_range, m)
        x2 = rng.uniform(-cfg.plant.w_max, cfg.plant.w_max, m)
        first = _first_inside(proof, simulate_batch(law, cfg.plant, x1, x2, steps))
        bound = _cell_bound(proof, x1, x2)
        proved = np.isfinite(bound)
        over += int(np.count_nonzero(proved & (first > bound)))
        worst = max(worst, int(first[proved].max()))
    return over, worst


@pytest.mark.parametrize("name", ["pd", "pto"])
def test_certified_bound_covers_simulation(name, pd_proof):
    proof = pd_proof if name == "pd" else nominal_proof(paper_config())
    over, worst = _bound_vs_simulation(proof, 40_000, seed=1)
    assert over == 0, f"{name}: {over} simulated states needed more samples than their bound"
    assert proof.bound_samples >= worst
    assert proof.simulation_over_bound == 0
    reach = proof.property("reach")
    assert reach.coverage >= 0.997, f"{name}: reach proved on only {reach.coverage:.4%}"


def test_certified_bound_covers_every_cell():
    """Every cell's corners and four seeded states inside it (225,000 states), stepped with
    the exact ZOH map (model.plant.step), no storage.

    The states of ``conftest.cell_states``: each proved cell is met at its four corners
    and inside: a bound one sample too low is caught in 1.5 times as many cells as by a
    million uniform states (measured in ``cell_states``).
    """
    from ptoverify.model.plant import step

    cfg = paper_config()
    proof = nominal_proof(cfg)
    law = make_law("pto", cfg)
    (p11, p12), (_, p22) = proof.target.P
    level = proof.target.c * (1 + 1e-9)
    x1, x2, bound = cell_states(proof.grid, proof.bound, 4, seed=2)
    assert np.isfinite(bound).sum() > 5 * np.isfinite(proof.bound).sum()
    live = np.flatnonzero(np.isfinite(bound))  # states not yet in the ellipse
    y1, y2 = x1[live], x2[live]
    for k in range(proof.bound_samples + 1):
        inside = p11 * y1 * y1 + 2 * p12 * y1 * y2 + p22 * y2 * y2 <= level
        assert np.all(inside | (k < bound[live])), (
            f"a state is outside the ellipse at its bound {k}"
        )
        live, y1, y2 = live[~inside], y1[~inside], y2[~inside]
        u, _r = law(y1, y2)
        y1, y2 = step(y1, y2, u, cfg.plant)
    assert live.size == 0, "a proved state never entered the ellipse"


def test_bound_covers_the_sweep_states():
    """The sweep's grid of initial states (200 x 200 over the envelope)."""
    from ptoverify.studies.sweep import SweepSettings

    cfg = paper_config()
    proof = nominal_proof(cfg)
    s = SweepSettings()
    x1, x2 = np.meshgrid(
        np.linspace(-cfg.plant.position_range, cfg.plant.position_range, s.n1),
        np.linspace(-cfg.plant.w_max, cfg.plant.w_max, s.n2),
    )
    x1, x2 = x1.ravel(), x2.ravel()
    b = simulate_batch(make_law("pto", cfg), cfg.plant, x1, x2, proof.bound_samples + 2)
    first, bound = _first_inside(proof, b), _cell_bound(proof, x1, x2)
    assert not np.any(np.isfinite(bound) & (first > bound)), "a sweep state exceeds its bound"


def test_pto_nominal_properties():
    proof = nominal_proof(paper_config())
    assert proof.property("input-bound").status == "proved"
    assert proof.property("no-stride-over-relaxed").status == "proved"
    assert proof.target.certified
    # what stays unproven for reach are cells whose images leave |x1| <= position_range
    region = proof.property("reach").unproven_region
    assert region is None or all(abs(c[0]) > 45 or abs(c[1]) > 45 for c in region["first_cells"])


def test_excursion_proves_reach_everywhere():
    proof = prove_law(paper_config(), "pd", excursion=1.0, n_random=500)
    assert proof.property("reach").status == "proved"
    assert proof.property("reach").coverage == 1.0


#: A coarse grid for the tests of refutations and of equal results across process layouts
#: (about 2,000 cells instead of 45,000): what they check does not need the fine grid.
COARSE = Resolution(h1=0.2, h2=20.0, h1_max=5.0, h_edge=0.5, steps=40)


def test_to_strict_stride_over_is_refuted_with_a_certified_counterexample():
    proof = prove_law(paper_config(), "to", n_random=0, res=COARSE)
    p = proof.property("no-stride-over-strict")
    assert p.status == "refuted"
    cex = p.counterexample
    assert cex.confirmed_by_simulation
    assert cex.sigma0 > 0 > cex.sigma1 or cex.sigma0 < 0 < cex.sigma1
    assert proof.property("reach").status != "proved"  # TO has no linear zone: no target


def test_sampled_unstable_linear_zone_never_proves():
    cfg = paper_config()
    bad = replace(cfg, pto=replace(cfg.pto, k2=6.0))
    proof = prove_law(bad, "pto", n_random=0)
    assert proof.property("reach").status != "proved"
    assert not proof.target.certified


def test_wrong_plant_a_does_not_prove_the_nominal_bound():
    """The law designed for a, driving a plant with 0.6 a: reach must not be proved as nominal."""
    cfg = paper_config()
    a = cfg.plant.a
    proof = prove_law(cfg, "pto", a_interval=(0.6 * a, 0.6 * a), n_random=0)
    nominal = nominal_proof(cfg)
    strict = proof.property("no-stride-over-strict").status
    assert strict != "proved" or proof.bound_samples != nominal.bound_samples


def test_certificate_checks_and_tampering_is_caught(pd_proof):
    cfg = paper_config()
    data = certificate_arrays(pd_proof, cfg)
    assert check_certificate(data, cfg, samples=60).ok
    finite = np.flatnonzero(np.isfinite(data["ball_bound"][0]) & (data["ball_bound"][0] > 5))
    tampered = dict(data, ball_bound=data["ball_bound"].copy())
    tampered["ball_bound"][0][finite[: len(finite) // 2]] -= 1
    assert not check_certificate(tampered, cfg, samples=5).ok, "lowered bounds went unnoticed"
    bigger = dict(data, c=np.array(float(data["c"]) * 1.5))
    assert not check_certificate(bigger, cfg, samples=5).ok, "a grown ellipse went unnoticed"
    img = data["image"].copy()
    img[:, 0] += 1e-6
    img[:, 1] -= 1e-6
    assert not check_certificate(dict(data, image=img), cfg, samples=40).ok, "shrunk images"


@pytest.mark.parametrize(
    "change",
    ["law xyz", "law pto", "params", "T", "no P", "no certified", "e1 str", "bound short"],
)
def test_a_forged_certificate_is_inconsistent_never_consistent(pd_proof, change):
    """Another law's name or parameters, a missing array, a wrong dtype or shape: exit 1
    ("inconsistent"), never "consistent" and never an internal error (audit R5)."""
    cfg = paper_config()
    data = dict(certificate_arrays(pd_proof, cfg))
    if change.startswith("law "):
        data["law"] = np.array(change.split()[1])
    elif change == "params":
        data["law_params"] = data["law_params"] * 1.01
    elif change == "T":
        data["T"] = np.array(0.001)
    elif change.startswith("no "):
        del data[change.split()[1]]
    elif change == "e1 str":
        data["e1"] = data["e1"].astype(str)
    else:
        data["bound"] = data["bound"][:10]
    res = check_certificate(data, cfg, samples=5)
    assert not res.ok and res.problems


def test_cli_prove_json_keys_and_check(tmp_path, capsys):
    out = tmp_path / "proof"
    assert main(["prove", "--law", "pd", "--json", "--out", str(out)]) == 0
    res = json.loads(capsys.readouterr().out)
    for key in (
        "properties",
        "target",
        "bound_samples",
        "simulated_worst_samples",
        "suboptimality",
        "cells",
        "timings_s",
        "backend",
    ):
        assert key in res, key
    for p in res["properties"].values():
        assert p["status"] in ("proved", "refuted", "unproven")
        assert {"coverage", "counterexample", "unproven_region"} <= set(p)
    assert set(res["suboptimality"]) == {"certified_max_ratio_nt", "excluded_radius"}
    assert set(res["target"]) >= {"P", "c"}
    cert = out / "certificate-pd.npz"
    assert (out / "proof-pd.png").stat().st_size > 0
    assert main(["prove", "--check", str(cert), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["check"]["ok"]
    with np.load(cert) as f:
        data = {k: f[k] for k in f.files}
    data["bound"] = data["bound"] - 1.0
    data["ball_bound"] = data["ball_bound"] - 1.0
    bad = tmp_path / "tampered.npz"
    np.savez(bad, **data)
    assert main(["prove", "--check", str(bad)]) == 1


@pytest.mark.parametrize("arg", ["0.5", "1.2,0.9", "a,b", "0,1"])
def test_bad_a_interval_is_input_error(arg):
    with pytest.raises(Exception) as info:
        parse_a_interval(arg, 100.0)
    assert type(info.value).__name__ == "InputError"
    assert main(["prove", "--a-interval", arg, "--law", "pd"]) == 2


def test_suboptimality_is_a_certified_upper_bound(pd_proof):
    """Where N* is computed exactly (discrete limit), bound / N* stays below the certified ratio."""
    from ptoverify.model.mintime import discrete_min_steps_batch

    cfg = paper_config()
    ratio = pd_proof.certified_max_ratio_nt
    assert ratio is not None and math.isfinite(ratio)
    rng = np.random.default_rng(3)
    r = pd_proof.excluded_radius
    x1 = rng.choice([-1, 1], 300) * rng.uniform(r, cfg.plant.position_range, 300)
    x2 = rng.uniform(-cfg.plant.w_max, cfg.plant.w_max, 300)
    n_star = discrete_min_steps_batch(x1, x2, cfg.plant).steps.astype(float)
    bound = _cell_bound(pd_proof, x1, x2)
    ok = np.isfinite(bound) & (n_star > 0)
    assert np.all(bound[ok] / n_star[ok] <= ratio + 1e-12)


def test_proof_gates_pass_at_the_paper_values():
    from ptoverify.studies.checks import run_checks

    verdicts = run_checks(paper_config(), ["proof-no-stride-over", "proof-reach"])
    assert [v.status for v in verdicts] == ["pass", "pass"], verdicts


def test_omega0_one_percent_larger_does_not_prove(monkeypatch):
    """The conformance mutant omega0 x 1.01 fails on a sliver at the zone's corner: no proof."""
    import ptoverify.studies.prove.run as prove_run

    real = prove_run.law_spec

    def spec(name, c):
        s = real(name, c)
        return replace(s, omega0=1.01 * s.omega0) if s.has_zone else s

    monkeypatch.setattr(prove_run, "law_spec", spec)
    proof = prove_law(paper_config(), "pto", n_random=0)
    assert proof.property("no-stride-over-strict").status != "proved"


@pytest.mark.parametrize("content", [b"", b"PK\x03\x04" + b"\x00" * 40, b"not a zip"])
def test_cli_check_of_a_file_that_is_no_npz_is_bad_input(tmp_path, capsys, content):
    """A truncated or empty certificate was an internal error (BadZipFile, EOFError)."""
    cert = tmp_path / "cert.npz"
    cert.write_bytes(content)
    assert main(["prove", "--check", str(cert)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("ptoverify: error: --check: cannot read")


@pytest.mark.parametrize(
    "change, words",
    [({"d": 50.0}, "fills the envelope"), ({"position_range": 1.0}, "proof cells")],
)
def test_a_configuration_the_grid_cannot_serve_is_bad_input(change, words):
    """Accepted configurations with no proof grid: one line naming the key (audit R4: an
    internal error in the cell graph before)."""
    from ptoverify.errors import InputError

    cfg = paper_config()
    if "d" in change:
        cfg = replace(cfg, pto=replace(cfg.pto, d=change["d"]))
    else:
        cfg = cfg.with_plant(position_range=change["position_range"])
    with pytest.raises(InputError, match=words):
        prove_law(cfg, "pto", n_random=0)


def test_suboptimality_map_bounds_the_exact_ratio_at_cell_corners(pd_proof):
    """The certified map (bound / N* lower bound per cell) is at least bound / exact N* at
    each corner of 300 seeded cells, and its maximum is the reported certified ratio."""
    from ptoverify.model.mintime import discrete_min_steps_batch

    cfg = paper_config()
    ratio = pd_proof.ratio_nt
    assert pd_proof.certified_max_ratio_nt == pytest.approx(float(np.nanmax(ratio)), rel=0)
    cells = np.flatnonzero(np.isfinite(ratio))
    pick = np.random.default_rng(3).choice(cells, 300, replace=False)
    x1lo, x1hi, x2lo, x2hi = (v[pick] for v in pd_proof.grid.boxes())
    for x1, x2 in ((x1lo, x2lo), (x1lo, x2hi), (x1hi, x2lo), (x1hi, x2hi)):
        n_star = discrete_min_steps_batch(x1, x2, cfg.plant).steps
        exact = pd_proof.bound[pick] / n_star
        assert np.all(ratio[pick] >= exact * (1 - 1e-12)), "the certified ratio is below the exact"
