"""The assignment engine: templates, seeded variants, verified keys, grading and outcome codes.

Pure engine: no database, no web (mechanics/ never imports app/). The web layer
(app/assignments/) stores what this package computes.

- `template`: the template model, read from TOML or JSON, its sha256;
- `variants`: a variant from a seed (sha256-driven: the same on every server);
- `keys` + `verify`: each part's key from the derivation, checked by sympy's LagrangesMethod;
- `grading`: a part's answer judged by mechanics.check, attempts, retry penalty, best score;
- `outcomes`: the stable outcome codes and the table that maps the checker's verdicts onto them.
"""
