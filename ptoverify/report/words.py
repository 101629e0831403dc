"""The report's words: one display name per law, one pluraliser, one claim title.

Every sentence, table cell and figure title of the report and of the plots names a
law by :func:`law_name` (never its id, ``pto-printed``), counts with
:func:`plural` (``1 reversal``, ``2 samples``; never ``1 reversals``) and names a
Section 6 claim by :func:`claim_title` (never its internal id).  Plain text, no
matplotlib (it imports only :mod:`ptoverify.report.render`): the sections, the
verdict and the plots all import it.

Catalogue
---------
LAW_WORDS    law id -> display name
law_name     a law's display name (the id when it has none)
plural       a count with its noun, singular or plural
claim_title  a claim's human title (the paper's words), from its record
display_unit the unit a claim's number is shown in (s -> ms, a count's noun)
claim_quantity a claim's number in its display unit (``1 sign reversal``, ``16.14 ms``)
claim_value_name what a claim's measured number is, in words (``phase delay``)
claim_measured_words a claim's measured number with what it is (``PD 36.41 % less``)
plain        a lower layer's sentence with the configuration file's jargon in words
gate_words   a gate's name in words, for prose
setting_words the gains a study ran at, in words
"""

from __future__ import annotations

import re
from collections.abc import Mapping

from ptoverify.counts import plural
from ptoverify.report.render import qty

__all__ = [
    "LAW_WORDS",
    "law_name",
    "plural",
    "claim_title",
    "display_unit",
    "claim_quantity",
    "claim_value_name",
    "claim_measured_words",
    "plain",
    "gate_words",
    "setting_words",
]

#: How each law is named in the report's text, tables and figure titles.
LAW_WORDS: dict[str, str] = {
    "to": "TO",
    "pd": "PD",
    "pto": "PTO (corrected)",
    "pto-printed": "PTO as printed",
    "ptos": "PTOS",
    "cascade-p": "cascade P",
}


def law_name(law: str) -> str:
    """Return a law's display name: ``pto-printed`` -> ``PTO as printed``.

    Parameters
    ----------
    law : str
        The law's id (``to``, ``pd``, ``pto``, ``pto-printed``, ``ptos``,
        ``cascade-p``); an unknown id (a user's law) is returned as is.

    Returns
    -------
    str

    Examples
    --------
    >>> law_name("pto-printed"), law_name("pto"), law_name("mine")
    ('PTO as printed', 'PTO (corrected)', 'mine')
    """
    return LAW_WORDS.get(law, law)


def claim_title(claim: Mapping) -> str:
    """Return a claim's human title: the paper's words it quotes (never its internal id).

    Parameters
    ----------
    claim : Mapping
        One entry of ``results.json``'s ``claims`` (``claim``: the paper's wording).

    Returns
    -------
    str

    Examples
    --------
    >>> claim_title({"id": "ramp-pd-lag", "claim": 'PD: "delays a large value"'})
    'PD: "delays a large value"'
    """
    return str(claim["claim"])


#: Claim units that count something: the noun each count is of.
COUNT_NOUNS = {"reversals": "sign reversal", "samples": "sample", "count": "state"}


def display_unit(unit: str) -> tuple[str, float]:
    """Return the unit a claim's number is shown in, and the factor from its stored unit.

    Parameters
    ----------
    unit : str
        The stored unit (``s``, ``mm``, ``deg``, ``%``, ``reversals``...).

    Returns
    -------
    tuple of (str, float)
        Times in ms; a count's plural noun (``sign reversals``).

    Examples
    --------
    >>> display_unit("s"), display_unit("reversals"), display_unit("mm")
    (('ms', 1000.0), ('sign reversals', 1.0), ('mm', 1.0))
    """
    if unit == "s":
        return "ms", 1e3
    if unit in COUNT_NOUNS:
        return COUNT_NOUNS[unit] + "s", 1.0
    return unit, 1.0


def claim_quantity(v: float | None, unit: str) -> str:
    """Return a claim's number in its display unit; a count with its noun in the right number.

    Parameters
    ----------
    v : float or None
        The value in the stored unit (None: not measured).
    unit : str
        The stored unit.

    Returns
    -------
    str

    Examples
    --------
    >>> claim_quantity(1.0, "reversals"), claim_quantity(0.01614, "s"), claim_quantity(None, "s")
    ('1 sign reversal', '16.14 ms', 'n/a')
    """
    if v is None:
        return "n/a"
    if unit in COUNT_NOUNS and float(v).is_integer():
        return plural(int(v), COUNT_NOUNS[unit])
    u, scale = display_unit(unit)
    return qty(v * scale, u)


#: Tokens of the claims' value names, as a reader writes them.
_TOKEN_WORDS = {"pto": "PTO", "pd": "PD", "to": "TO", "rms": "RMS"}


def claim_value_name(c: Mapping) -> str:
    """Return what a claim's measured number is, in words, without its unit.

    The name of the primary reading's value that equals the claim's number, with
    its unit suffix dropped (``phase_delay_deg`` -> ``phase delay``).

    Parameters
    ----------
    c : Mapping
        A claim of ``results["claims"]`` (``measured``, ``readings``).

    Returns
    -------
    str
        The words; empty when the number is not measured or no value matches.

    Examples
    --------
    >>> claim_value_name({"measured": -3.0, "readings": [{"values": {"pd_more_percent": -3.0}}]})
    'PD more'
    """
    if c["measured"] is None:
        return ""
    values = c["readings"][0]["values"] if c["readings"] else {}
    name = next(
        (k for k, v in values.items() if isinstance(v, (int, float)) and v == c["measured"]), ""
    )
    return " ".join(
        _TOKEN_WORDS.get(w, w) for w in re.sub(r"_(mm_s|mm|s|deg|percent)$", "", name).split("_")
    ).strip()


def claim_measured_words(c: Mapping) -> str:
    """Return a claim's measured number with what it is, a negative 'more' read as 'less'.

    Parameters
    ----------
    c : Mapping
        A claim of ``results["claims"]`` (``measured``, ``unit``, ``readings``).

    Returns
    -------
    str
        ``<what> <number with unit>`` (``phase delay 0.3822 deg``); a value named
        ``... more`` that is negative reads ``... <|number|> less`` (``PD 36.41 %
        less``); a count is its number with its noun (``1 sign reversal``);
        ``n/a`` when not measured.

    Examples
    --------
    >>> c = {"measured": -36.4, "unit": "%",
    ...      "readings": [{"values": {"pd_more_percent": -36.4}}]}
    >>> claim_measured_words(c)
    'PD 36.4 % less'
    """
    v, name = c["measured"], claim_value_name(c)
    if v is None:
        return "n/a"
    if name.endswith(" more") and v < 0:
        return f"{name[: -len(' more')]} {claim_quantity(-v, c['unit'])} less"
    if name.endswith(" more"):
        return f"{name[: -len(' more')]} {claim_quantity(v, c['unit'])} more"
    if c["unit"] in COUNT_NOUNS:
        return claim_quantity(v, c["unit"])
    return f"{name} {claim_quantity(v, c['unit'])}".strip()


#: Configuration-file jargon (a TOML table's name) and the words a reader knows.
_JARGON = (
    (re.compile(r"\[robustness\] box"), "perturbation box"),
    (re.compile(r"\[robustness\] (\w+)"), lambda m: "the " + m.group(1).replace("_", " ")),
    (re.compile(r"\[(\w+)\] table"), lambda m: f"the configuration's {m.group(1)} settings"),
)


def plain(text: str) -> str:
    """Return text with the configuration file's jargon in words (``[robustness] box``).

    Parameters
    ----------
    text : str
        A sentence written by a lower layer (a gate's description).

    Returns
    -------
    str

    Examples
    --------
    >>> plain("anywhere in the [robustness] box (true a)")
    'anywhere in the perturbation box (true a)'
    >>> plain("limit from [robustness] settling_ratio_limit")
    'limit from the settling ratio limit'
    """
    for pattern, words in _JARGON:
        text = pattern.sub(words, text)
    return text


def gate_words(name: str) -> str:
    """Return a gate's name in words: ``robust-no-limit-cycle`` -> ``no limit cycle (perturbed plant)``.

    Parameters
    ----------
    name : str
        The gate's stable name (the gate table's first column).

    Returns
    -------
    str

    Examples
    --------
    >>> gate_words("robust-settling"), gate_words("odd-symmetry")
    ('settling (perturbed plant)', 'odd symmetry')
    """
    if name.startswith("robust-"):
        return name.removeprefix("robust-").replace("-", " ") + " (perturbed plant)"
    return name.replace("-", " ")


def setting_words(setting: str) -> str:
    """Return the gains a study ran at in words: ``tuned pto-paper`` -> ``each law at its best ...``.

    Parameters
    ----------
    setting : str
        ``configured`` or ``tuned <bound>``, a bound of
        :data:`ptoverify.studies.tune.fair.FAIR_BOUNDS`.

    Returns
    -------
    str

    Examples
    --------
    >>> setting_words("configured")
    'each law at the configured gains'
    >>> setting_words("tuned pto-paper")
    "each law at its best tuning, overshoot <= the PTO's overshoot at the paper's gains"
    """
    from ptoverify.studies.tune.fair import FAIR_BOUNDS

    if setting == "configured":
        return "each law at the configured gains"
    if setting.startswith("tuned "):
        bound = setting.removeprefix("tuned ")
        return f"each law at its best tuning, overshoot <= {FAIR_BOUNDS.get(bound, bound)}"
    return setting
