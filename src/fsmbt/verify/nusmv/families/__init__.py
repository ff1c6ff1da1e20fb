"""The NuSMV rules of the node families, keyed by the same names as the interpreter's
(``fsmbt.semantics.families``; the node registry's ``handler`` / ``nusmv`` fields). ``registry``
holds the table ``encode_bt`` dispatches on beside its own rules; ``builtin_rules`` the loops and
parallels (docs/semantics.md, "Node families"; docs/nusmv.md).

This ``__init__`` imports nothing, so its modules import each other without a cycle.
"""
