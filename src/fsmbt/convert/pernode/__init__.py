"""The per-node conversion's rules, one module per node family, in the layout of
``fsmbt.semantics.families`` and ``fsmbt.verify.nusmv.families`` (BehaviorTree.CPP's: one
source file per node family, the contract in its header): ``sequence`` (Sequence, Fallback,
their with-memory and asynchronous kinds), ``reactive``, ``parallel`` (Parallel, ParallelAll),
``status_map`` (Inverter, ForceSuccess, ForceFailure, KeepRunningUntilFailure), ``loops``
(Repeat, RetryUntilSuccessful). ``kernel`` holds what they share - continuations, the writer's
contract (``RegionWriter``), the ``NodeRule`` a family declares - and ``writer`` the one
writer that walks a region and dispatches on ``registry.RULES`` by the declaration's
``handler`` name. ``sizing`` estimates a region before the converter chooses its form.

The front door is ``fsmbt.convert.bt_pernode`` (docs/conversion.md, "Per-node conversion").
This ``__init__`` imports nothing, so a family module and the registry import each other's
package without a cycle.
"""
