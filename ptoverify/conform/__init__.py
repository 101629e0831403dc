"""The conformance layer: gate a third-party PTO implementation against the reference.

Catalogue
---------
gate       conform: the verdict for a callable or a table
agreement  conformance grid (--emit-grid), CSV tables, per-region agreement
userlaw    loading a user law, its mode, real-number outputs, copies of its inputs
isolation  the law in a child process: time, memory and lifetime limits (IsolatedLaw)
findings   the failure entry every property reports (light: the law's process loads it)
reaper     the law's supervisor (a subreaper): nothing the law starts outlives the run
evidence   the evidence behind a conform verdict (maps, responses, settling / N* T)
testing    assert_conforms, for a team's own pytest suite (re-exported as ptoverify.testing)
junit      JUnit XML from verdicts (check --junit, conform --junit)
"""
