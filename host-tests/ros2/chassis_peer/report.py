"""Figures the end-to-end tests measure, printed in pytest's summary (`conftest.py`)."""

drift: list[tuple[str, str, float, float, float, float]] = []
"""(generation, path, position error m, heading error rad, path length m, position bound m) for
each odometry run."""

stops: list[tuple[str, str, float]] = []
"""(generation, what stopped it, ms from the cause (the last `/cmd_vel` sent, the signal sent)
to the simulator's pose first seen at its final value)."""


def lines() -> list[str]:
    """The figures as Markdown tables."""
    out = []
    if drift:
        out += [
            "| firmware | path | length | position error (bound) | heading error |",
            "|---|---|---:|---:|---:|",
        ]
        for gen, path, pos, head, length, bound in sorted(drift):
            out.append(
                f"| {gen} | {path} | {length:.2f} m | {pos * 1000:.1f} mm ({bound * 1000:.0f} mm) "
                f"| {head:.4f} rad |"
            )
    if stops:
        out += [""] if out else []
        out += ["| firmware | cause | stopped after |", "|---|---|---:|"]
        for gen, cause, ms in sorted(stops):
            out.append(f"| {gen} | {cause} | {ms:.0f} ms |")
    return out
