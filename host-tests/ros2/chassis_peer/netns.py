"""The private network namespace the tests run in.

`enter()` moves this process into a new network namespace of its own (what `unshare -n` does,
through the same system call), brings its loopback interface up and checks that loopback is the
only interface there. Every process started afterwards (the simulator, the node) inherits the
namespace, so no DDS packet of the tests can leave it.

It must run before any thread exists (a namespace change applies to the calling thread only):
the test suite's `conftest.py` calls it when pytest loads it, before Cyclone DDS starts.
"""

import ctypes
import os
import subprocess

CLONE_NEWNET = 0x40000000
"""`unshare(2)`'s flag for a new network namespace."""

_entered = False


class NamespaceError(RuntimeError):
    """The private network namespace could not be made, or is not private."""


def interfaces() -> list[str]:
    """The network interfaces of this process's namespace, as `ip -brief addr` lists them."""
    out = subprocess.run(
        ["ip", "-brief", "addr"], check=True, capture_output=True, text=True
    ).stdout
    return [line.split()[0] for line in out.splitlines() if line.strip()]


def _threads() -> int:
    return len(os.listdir("/proc/self/task"))


def enter() -> None:
    """Moves this process into a new network namespace with only `lo`, up.

    Raises `NamespaceError` with the reason if the system refuses (no `CAP_SYS_ADMIN`: run as
    root), if this process already has threads, or if the namespace has any interface but `lo`.
    """
    global _entered
    if _entered:
        return
    if _threads() != 1:
        raise NamespaceError(
            f"this process already runs {_threads()} threads: the network namespace must be "
            "entered before any starts"
        )
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.unshare(CLONE_NEWNET) != 0:
        errno = ctypes.get_errno()
        raise NamespaceError(
            f"unshare(CLONE_NEWNET) refused: {os.strerror(errno)} (a private network namespace "
            "needs root or CAP_SYS_ADMIN, as `unshare -n` does)"
        )
    subprocess.run(["ip", "link", "set", "lo", "up"], check=True)
    seen = interfaces()
    if seen != ["lo"]:
        raise NamespaceError(f"the new network namespace lists {seen}, not only lo")
    _entered = True


def entered() -> bool:
    """Whether `enter()` succeeded in this process."""
    return _entered
