"""What this machine lets a process use: the memory it can still allocate, read from the kernel
(/proc/meminfo, memory cgroups v1 and v2, ``ulimit`` limits), and byte counts as text."""

from __future__ import annotations

import os
import resource


def available_memory() -> float | None:
    """Memory this process can still allocate [bytes], or None when unknown.

    The smallest of: the kernel's MemAvailable, the free part of the memory
    cgroup's limit (v1 or v2, the process's group and its parents), and the
    address-space and data-segment limits (``ulimit -v``, ``-d``) minus what
    the process already uses.
    """
    candidates = []
    meminfo = _read_kib("/proc/meminfo")
    if "MemAvailable" in meminfo:
        candidates.append(meminfo["MemAvailable"])
    candidates.extend(_cgroup_free())
    status = _read_kib("/proc/self/status")
    for limit, used in ((resource.RLIMIT_AS, "VmSize"), (resource.RLIMIT_DATA, "VmData")):
        soft = resource.getrlimit(limit)[0]
        if soft != resource.RLIM_INFINITY and used in status:
            candidates.append(max(0.0, soft - status[used]))
    if not candidates:
        try:
            candidates.append(float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")))
        except (ValueError, OSError, AttributeError):
            return None
    return float(min(candidates))


def _read_kib(path: str) -> dict[str, float]:
    """``Name: value kB`` lines of a /proc file, in bytes ({} if unreadable)."""
    out = {}
    try:
        with open(path) as handle:
            for line in handle:
                name, _, rest = line.partition(":")
                parts = rest.split()
                if len(parts) == 2 and parts[1] == "kB" and parts[0].isdigit():
                    out[name] = 1024.0 * int(parts[0])
    except OSError:
        pass
    return out


def _read_number(path: str) -> float | None:
    try:
        with open(path) as handle:
            text = handle.read().strip()
        return float(text) if text.isdigit() else None
    except OSError:
        return None


def _cgroup_free() -> list[float]:
    """Limit minus non-reclaimable usage of each limited memory cgroup of this process [bytes]."""
    free: list[float] = []
    try:
        with open("/proc/self/cgroup") as handle:
            lines = handle.read().splitlines()
    except OSError:
        return free
    for line in lines:
        _, controllers, path = line.split(":", 2)
        if controllers == "":  # v2
            root, names = "/sys/fs/cgroup", ("memory.max", "memory.current", "inactive_file")
        elif "memory" in controllers.split(","):
            root = "/sys/fs/cgroup/memory"
            names = ("memory.limit_in_bytes", "memory.usage_in_bytes", "total_inactive_file")
        else:
            continue
        parts = [p for p in path.split("/") if p]
        for depth in range(len(parts), -1, -1):
            group = os.path.join(root, *parts[:depth])
            limit = _read_number(os.path.join(group, names[0]))
            usage = _read_number(os.path.join(group, names[1]))
            if limit is None or usage is None or limit >= 2.0**60:
                continue
            inactive = 0.0
            try:
                with open(os.path.join(group, "memory.stat")) as handle:
                    for stat_line in handle:
                        key, _, value = stat_line.partition(" ")
                        if key == names[2] and value.strip().isdigit():
                            inactive = float(value)
            except OSError:
                pass
            free.append(max(0.0, limit - max(0.0, usage - inactive)))
    return free


def format_bytes(value: float) -> str:
    """A byte count as text: 3 significant digits and kB, MB, GB or TB."""
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6)):
        if value >= size:
            return f"{value / size:.3g} {unit}"
    return f"{value / 1e3:.3g} kB"
