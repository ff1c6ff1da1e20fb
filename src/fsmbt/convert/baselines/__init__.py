"""The paper's classical baselines as conversion engines: ``bsd`` (Colledanchise & Ögren's
state-variable mapping) and ``chds`` (Marzinotto et al.'s BT <-> CHDS mappings). Importing this
package registers both in ``fsmbt.convert.engines`` (it is one of the registry's plugin
modules). See docs/baselines.md."""

from fsmbt.convert.baselines import bsd, chds

__all__ = ["bsd", "chds"]
