"""python-statemachine classes: read statically (never imported or run) and written
(docs/formats/pystatemachine.md). Detected by an ``import statemachine`` /
``from statemachine import`` line."""
