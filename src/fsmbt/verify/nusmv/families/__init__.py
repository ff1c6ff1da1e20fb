"""The NuSMV rules of the node families, one module per family in the BehaviorTree.CPP layout
(one source file per node family, the rule's contract in its header), named as the
interpreter's family modules (``fsmbt.semantics.families``) and keyed by the same rule names
(the node registry's ``handler`` / ``nusmv`` fields): ``sequence``, ``reactive``, ``parallel``,
``conditional``, ``status_map``, ``loops``, ``once``, ``wrappers``, ``manual``, ``nav2``,
``gates``. Each exports ``RULES``; ``registry`` merges them into the table ``encode_bt``
dispatches on; ``contract`` is the calling convention and the encoder protocol the rules write
through, ``common`` what they share (docs/semantics.md, "Node families"; docs/nusmv.md, "Where
the rules live").

This ``__init__`` imports nothing, so its modules import each other without a cycle.
"""
