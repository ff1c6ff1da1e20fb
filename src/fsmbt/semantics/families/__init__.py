"""The node families' behaviour, one module per family, in the BehaviorTree.CPP layout (one
source file per node family, the contract in its header): ``sequence`` (Sequence and Fallback),
``reactive``, ``parallel``, ``conditional``, ``status_map``, ``loops``, ``once``, ``wrappers``,
``manual``, ``nav2``, ``gates``. Each module holds its family's tick rules and the reading and
structural check of its ports, and lists them in its ``RULES`` table; ``registry`` merges the
tables into the one the interpreter dispatches on (docs/semantics.md, "Node families": how to
add a node kind, with a worked example).

The declaration of each kind (its name, child count, memory at rest, halt rule, NuSMV rule
name) stays in ``fsmbt.model.nodes``, which the readers need below this layer; a family's rules
here are keyed by the declaration's ``handler`` name, and the NuSMV rules in
``fsmbt.verify.nusmv.families`` by the same names.

This ``__init__`` imports nothing, so a family module and the registry import each other's
package without a cycle.
"""
