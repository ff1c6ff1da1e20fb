"""Where fsmbt keeps what it builds once per machine (NuSMV, BehaviorTree.CPP, the C++ driver).

Why outside the checkout: a clean checkout (CI, a fresh clone) must not rebuild a 4-minute
NuSMV or a 7-minute BehaviorTree.CPP; each build lands in a folder keyed by its version under
this root, and the build scripts (scripts/build_nusmv.sh, scripts/build_btcpp.sh) use the same
rule.
"""

from __future__ import annotations

import os
from pathlib import Path


def cache_root() -> Path:
    """``$FSMBT_CACHE``, else ``$XDG_CACHE_HOME/fsmbt``, else ``~/.cache/fsmbt``."""
    explicit = os.environ.get("FSMBT_CACHE")
    if explicit:
        return Path(explicit)
    xdg = os.environ.get("XDG_CACHE_HOME")
    return (Path(xdg) if xdg else Path.home() / ".cache") / "fsmbt"


#: The BehaviorTree.CPP version the build script installs.
BTCPP_VERSION = "4.8.2"
#: Its cache folder's key: the version and the build options that change what is installed
#: (``-sqlite``: built with ``BTCPP_SQLITE_LOGGING=ON``, so the driver can write ``.db3`` logs).
#: Must equal ``BTCPP_BUILD`` in src/fsmbt/install/build_btcpp.sh; a new key makes every machine
#: build once into a new folder and leaves the old one untouched.
BTCPP_BUILD = f"{BTCPP_VERSION}-sqlite"


def btcpp_prefix() -> Path:
    """Where the build script installs BehaviorTree.CPP (may not exist): ``btcpp-4.8.2-sqlite``
    under ``cache_root()``. The C++ runtime (``fsmbt.runtime.cpp``) and the load check
    (``fsmbt.semantics.engines.btcpp_load``) both find it here."""
    return cache_root() / f"btcpp-{BTCPP_BUILD}"
