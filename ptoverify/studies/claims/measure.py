"""What each Section 6 claim measures, on the exactly simulated loop."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ptoverify.config import Config
from ptoverify.counts import plural
from ptoverify.model.laws import Law, make_law
from ptoverify.model.memo import memo
from ptoverify.sim import metrics as mt
from ptoverify.sim.exact import Compared, ExactMetrics, exact_metrics
from ptoverify.sim.simulate import SimResult, simulate
from ptoverify.verdict import time_order

from .types import (
    _FLOORS,
    _SIM_TRACKING,
    MUCH,
    PHASE_FLOOR_DEG,
    REL_TOL,
    _more_or_less,
    numeric_verdict,
)

if TYPE_CHECKING:
    from .types import Outcome, Reading


def _cfg_for(cfg: Config, reading: Reading) -> Config:
    return cfg.with_plant(a=cfg.bandwidth_hz) if reading.a == "f" else cfg


@memo(maxsize=64)
def _law(name: str, cfg: Config) -> Law:
    return make_law(name, cfg)


@memo(maxsize=256)
def _sim(cfg: Config, law: str, signal: str, tracking: str) -> SimResult:
    return simulate(_law(law, cfg), cfg.plant, signal, tracking=_SIM_TRACKING[tracking])


@memo(maxsize=512)
def _metrics(cfg: Config, law: str, signal: str, tracking: str, frac: float) -> ExactMetrics:
    res = _sim(cfg, law, signal, tracking)
    return exact_metrics(res, cfg.plant, res.reference, step_fraction=frac)


class _Ctx:
    """Access to the responses under one reading."""

    def __init__(
        self,
        cfg: Config,
        reading: Reading,
        paper: dict[str, float | None],
        grid: bool = False,
        law_cfg: dict[str, Config] | None = None,
    ):
        self.cfg = _cfg_for(cfg, reading)
        self.law_cfg = law_cfg or {}  # law -> its (tuned) configuration, else self.cfg
        self.reading = reading
        self.paper = paper  # claim id -> the registry's paper value
        self.tracking = reading.tracking or "feed-forward"
        self.pto = "pto-printed" if reading.pto == "printed" else "pto"
        self.vband = self.cfg.plant.a * mt.TIGHT_BAND
        self.grid = grid  # decide on the sample-grid values instead of the exact ones
        self.ties: list[str] = []  # true ties met by the comparisons of this pass

    def sim(self, law: str, signal: str) -> SimResult:
        name = self.pto if law == "pto" else law
        cfg = self.law_cfg.get(law, self.cfg)
        return _sim(cfg, name, signal, self.tracking if signal != "step" else "feed-forward")

    def tail(self, law: str, signal: str, what: str = "e") -> np.ndarray:
        r = self.sim(law, signal)
        y = r.e if what == "e" else r.x2 - r.r_dot
        return y[y.size // 2 :]

    def oscillates(self, law: str, signal: str, what: str = "e") -> tuple[bool, float, int]:
        band = mt.TIGHT_BAND if what == "e" else self.vband
        y = self.tail(law, signal, what)
        amp, rev = mt.oscillation_amplitude(y), mt.sign_reversals(y, band)
        return amp > band and rev >= 2, amp, rev

    def metric(self, law: str, signal: str, key: str) -> Compared:
        """Return a time metric of a response, exact and on the grid (:mod:`ptoverify.sim.exact`)."""
        name = self.pto if law == "pto" else law
        tracking = self.tracking if signal != "step" else "feed-forward"
        frac = self.reading.band if self.reading.band is not None else mt.STEP_FRACTION
        cfg = self.law_cfg.get(law, self.cfg)
        return _metrics(cfg, name, signal, tracking, frac).values[key]

    def value(self, m: Compared) -> float:
        """Return the value this pass decides on: exact, or the grid value in the grid pass."""
        return m.grid if self.grid else m.exact

    def settling(self, law: str, key: str = "settling_2pct_s") -> float:
        return self.value(self.metric(law, "step", key))

    def overshoot(self, law: str, signal: str = "step") -> float:
        return self.value(self.metric(law, signal, "overshoot_mm"))

    def sine(self, law: str) -> tuple[float, float]:
        """Phase delay [deg] (between samples) and RMS of x1 minus its fundamental [mm]."""
        r = self.sim(law, "sine")
        f = r.reference.frequency  # the simulated sine's own frequency
        out = mt.sine_fit(r.t, r.x1, f, t_from=1.0 / f)
        return self.value(self.metric(law, "sine", "phase_delay_deg")), out.residual_rms

    def less(self, law_a: str, law_b: str, signal: str, key: str, names: tuple[str, str]) -> bool:
        """Whether law_a's time metric is below law_b's by the tie rule; a tie is recorded.

        The one tie rule of the suite (:func:`ptoverify.verdict.time_order`,
        :data:`ptoverify.verdict.TIME_TIE_RULE`): two times less than one sample
        period apart tie, exact and grid values alike (grid values tie only when
        equal); two exact values closer than their summed accuracies
        (:meth:`ptoverify.sim.exact.Compared.compare`) tie as well.
        """
        a, b = self.metric(law_a, signal, key), self.metric(law_b, signal, key)
        x, y = (a.grid, b.grid) if self.grid else (a.exact, b.exact)
        order = time_order(x, y, self.cfg.plant.sample_time)
        if order is not None and a.compare(b, grid=self.grid) == 0:
            order = 0  # not told apart to the precision they are computed to
        if order == 0:
            self.ties.append(f"{names[0]} = {names[1]} (less than one sample apart)")
        return order == -1


def _near(measured: float, cl: _Claim) -> bool:
    """Apply the numeric rule against the registry's paper value and the unit's floor."""
    return numeric_verdict(measured, cl.paper_value, _FLOORS[cl.unit][0])


def _ms(x: float) -> str:
    return "never" if not math.isfinite(x) else f"{1e3 * x:.2f} ms"


# ------------------------------------------------------------------ the claims
def _step_to_osc(c: _Ctx, cl: _Claim) -> Outcome:
    ok, amp, rev = c.oscillates("to", "step")
    return (
        amp,
        {"amplitude_mm": amp, "reversals": rev},
        ok,
        f"TO error over the last half: amplitude {amp:.4f} mm, {plural(rev, 'sign reversal')}",
    )


def _step_pd_31(c: _Ctx, cl: _Claim) -> Outcome:
    ts_pd, ts_pto = c.settling("pd"), c.settling("pto")
    os_pd, os_pto = c.overshoot("pd"), c.overshoot("pto")
    more = 100.0 * (ts_pd / ts_pto - 1.0) if ts_pto > 0 else math.nan
    vals = {
        "settling_pd_s": ts_pd,
        "settling_pto_s": ts_pto,
        "overshoot_pd_mm": os_pd,
        "overshoot_pto_mm": os_pto,
        "pd_more_percent": more,
    }
    ok = _near(more, cl)
    return (
        more,
        vals,
        ok,
        (
            f"settling PD {_ms(ts_pd)} vs PTO {_ms(ts_pto)}: PD needs "
            f"{_more_or_less(more)}; overshoot PD {os_pd:.3f} mm, PTO {os_pto:.3f} mm"
        ),
    )


def _step_pto_between(c: _Ctx, cl: _Claim) -> Outcome:
    _, a_pto, _ = c.oscillates("pto", "step")
    _, a_to, _ = c.oscillates("to", "step")
    ts_pto, ts_pd = c.settling("pto"), c.settling("pd")
    names = ("settling_pto_s", "settling_pd_s")
    ok = a_pto < a_to and c.less("pto", "pd", "step", "settling_2pct_s", names)
    return (
        None,
        {
            "steady_amplitude_pto_mm": a_pto,
            "steady_amplitude_to_mm": a_to,
            "settling_pto_s": ts_pto,
            "settling_pd_s": ts_pd,
        },
        ok,
        (
            f"steady amplitude PTO {a_pto:.4f} mm vs TO {a_to:.4f} mm; settling PTO {_ms(ts_pto)}"
            f" vs PD {_ms(ts_pd)}"
        ),
    )


def _ramp_to_osc(c: _Ctx, cl: _Claim) -> Outcome:
    okp, ap, rp = c.oscillates("to", "ramp", "e")
    okv, av, rv = c.oscillates("to", "ramp", "v")
    return (
        ap,
        {
            "position_amplitude_mm": ap,
            "position_reversals": rp,
            "velocity_amplitude_mm_s": av,
            "velocity_reversals": rv,
        },
        okp and okv,
        (
            f"TO last half: position error {ap:.4f} mm ({plural(rp, 'sign reversal')}), velocity "
            f"error {av:.2f} mm/s ({plural(rv, 'sign reversal')})"
        ),
    )


def _ramp_pd_lag(c: _Ctx, cl: _Claim) -> Outcome:
    r = c.sim("pd", "ramp")
    lag = mt.ramp_lag(r.t, r.e, r.r_dot)
    slope = r.reference.speed
    d = c.cfg.pto.d
    return (
        lag,
        {"lag_mm": lag, "lag_s": lag / slope, "d_mm": d},
        lag > d,
        f"PD mean ramp error {lag:.3f} mm ({1e3 * lag / slope:.2f} ms) vs d = {d:g} mm",
    )


def _ramp_pto_smooth(c: _Ctx, cl: _Claim) -> Outcome:
    r = c.sim("pto", "ramp")
    rev = mt.sign_reversals(r.e, mt.TIGHT_BAND)
    ts = c.value(c.metric("pto", "ramp", "settling_0p01mm_s"))
    ok = rev == 0 and math.isfinite(ts)
    return (
        float(rev),
        {
            "error_reversals": rev,
            "settling_0p01mm_s": ts,
            "overshoot_mm": c.overshoot("pto", "ramp"),
        },
        ok,
        f"PTO ramp error: {plural(rev, 'sign reversal')} outside 0.01 mm; settles to 0.01 mm "
        f"at {_ms(ts)}",
    )


def _sine_to(c: _Ctx, cl: _Claim) -> Outcome:
    delay, rms = c.sine("to")
    ok = abs(delay) <= PHASE_FLOOR_DEG and rms > mt.TIGHT_BAND
    return (
        delay,
        {"phase_delay_deg": delay, "residual_rms_mm": rms},
        ok,
        f"TO phase delay {delay:.2f} deg; x1 minus fundamental RMS {rms:.4f} mm",
    )


def _sine_delay(law: str) -> Callable[[_Ctx, _Claim], Outcome]:
    def measure(c: _Ctx, cl: _Claim) -> Outcome:
        delay, rms = c.sine(law)
        return (
            delay,
            {"phase_delay_deg": delay, "residual_rms_mm": rms},
            _near(delay, cl),
            f"{law.upper()} phase delay {delay:.2f} deg",
        )

    return measure


def _sine_ratio(c: _Ctx, cl: _Claim) -> Outcome:
    d_pto, _ = c.sine("pto")
    d_pd, _ = c.sine("pd")
    ratio = 100.0 * d_pto / d_pd if d_pd != 0 else math.nan
    p_pto, p_pd = c.paper["sine-pto-delay"], c.paper["sine-pd-delay"]
    return (
        ratio,
        {"phase_delay_pto_deg": d_pto, "phase_delay_pd_deg": d_pd, "ratio_percent": ratio},
        _near(ratio, cl),
        (
            f"PTO {d_pto:.2f} deg / PD {d_pd:.2f} deg = {ratio:.1f} % (the paper's own numbers "
            f"give {100 * p_pto / p_pd:.1f} %)"
        ),
    )


def _sine_fluctuant(c: _Ctx, cl: _Claim) -> Outcome:
    rms = {law: c.sine(law)[1] for law in ("to", "pd", "pto")}
    other = max(rms["pd"], rms["pto"])
    ok = rms["to"] >= MUCH * other
    return (
        rms["to"],
        {f"residual_rms_{k}_mm": v for k, v in rms.items()},
        ok,
        (
            f"x1 minus fundamental RMS: TO {rms['to']:.4f}, PD {rms['pd']:.4f}, PTO "
            f"{rms['pto']:.4f} mm"
        ),
    )


def _conclusion(c: _Ctx, cl: _Claim) -> Outcome:
    osc_pto, a_pto, _ = c.oscillates("pto", "step")
    osc_to, a_to, _ = c.oscillates("to", "step")
    os_pto, os_to = c.overshoot("pto"), c.overshoot("to")
    ts_pto, ts_pd = c.settling("pto"), c.settling("pd")
    quicker = c.less("pto", "pd", "step", "settling_2pct_s", ("settling_pto_s", "settling_pd_s"))
    ok = (not osc_pto) and osc_to and os_pto <= mt.TIGHT_BAND < os_to and quicker
    return (
        None,
        {
            "steady_amplitude_pto_mm": a_pto,
            "steady_amplitude_to_mm": a_to,
            "overshoot_pto_mm": os_pto,
            "overshoot_to_mm": os_to,
            "settling_pto_s": ts_pto,
            "settling_pd_s": ts_pd,
        },
        ok,
        (
            f"step: PTO {'oscillates' if osc_pto else 'does not oscillate'} (amplitude "
            f"{a_pto:.4f} mm), TO {'oscillates' if osc_to else 'does not'}; overshoot "
            f"PTO {os_pto:.3f} mm, TO {os_to:.3f} mm; settling PTO {_ms(ts_pto)} vs PD "
            f"{_ms(ts_pd)}"
        ),
    )


def _quicker(c: _Ctx, cl: _Claim) -> Outcome:
    rt = {law: c.value(c.metric(law, "step", "rise_time_s")) for law in ("pto", "pd")}
    ok = c.less("pto", "pd", "step", "rise_time_s", ("rise_time_pto_s", "rise_time_pd_s"))
    return (
        rt["pto"],
        {"rise_time_pto_s": rt["pto"], "rise_time_pd_s": rt["pd"]},
        ok,
        f"10-90 % rise time PTO {_ms(rt['pto'])} vs PD {_ms(rt['pd'])}",
    )


@dataclass(frozen=True)
class _Claim:
    """A registry entry: the paper's words and number, and how to measure them.

    ``paper_value`` is the only place a paper number is written; the verdict
    (:func:`_near`) and the rule text (:attr:`rule`) read it from here.
    ``note`` is the rule of a qualitative claim, or a remark appended to the
    numeric rule.
    """

    id: str
    section: str
    signal: str
    claim: str
    paper_value: float | None
    unit: str
    note: str
    dims: tuple[str, ...]
    measure: Callable[[_Ctx, _Claim], Outcome]

    @property
    def rule(self) -> str:
        """The tolerance rule that decides the verdict, in words."""
        if self.paper_value is None:
            return self.note
        p, floor = self.paper_value, _FLOORS[self.unit][1]
        text = f"|measured - {p:g}| <= max({100 * REL_TOL:g} % of {p:g}, {floor})"
        return f"{text}; {self.note}" if self.note else text
