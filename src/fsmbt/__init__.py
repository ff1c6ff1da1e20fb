"""fsmbt: convert behavior models between finite state machines and behavior trees, and prove it.

One data flow: read -> model -> convert -> verify -> write / render. Every interface (CLI, web,
batch) calls the same library functions.
"""

__version__ = "0.1.0"
