"""The whole suite runs in a private network namespace: made here, as pytest starts and before
any thread or DDS participant exists, so that no DDS packet of the tests leaves this machine's
loopback, and the simulator and the node, started later, inherit it."""

import pytest

from chassis_peer import netns


def pytest_configure(config: pytest.Config) -> None:
    try:
        netns.enter()
    except netns.NamespaceError as e:
        pytest.exit(f"cannot make the private network namespace: {e}", returncode=4)
    except FileNotFoundError as e:
        pytest.exit(f"cannot make the private network namespace: `ip` is missing ({e})", 4)


def pytest_terminal_summary(terminalreporter) -> None:
    from chassis_peer import report

    lines = report.lines()
    if lines:
        terminalreporter.section("the node against the simulator")
        for line in lines:
            terminalreporter.write_line(line)
