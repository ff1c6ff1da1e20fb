"""pytransitions configurations (the ``MarkupMachine`` dict, as JSON or YAML): read and written
(docs/formats/transitions.md).

The text is data (``json`` / ``yaml.safe_load``), never code. Detected by the extensions
``.transitions.json`` / ``.transitions.yaml`` / ``.transitions.yml`` or by content: a top-level
mapping with ``states`` and ``transitions`` whose transitions name a ``trigger``.
"""
