"""The output layer: collect results once, build sections, render, plot.

Catalogue
---------
collect         collect (every result once), write_report (atomic)
sections        the report's sections, built from the collected results
render          Section, Block; render_html, render_markdown
plots           every figure, drawn from results passed in (a package; the only matplotlib user)
conform_report  conform --report DIR: the user's law as an HTML/Markdown/JSON report
"""
