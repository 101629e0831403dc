"""The hostile audit is a script, not a test module: pytest never imports it."""

collect_ignore = ["run_audit.py"]
