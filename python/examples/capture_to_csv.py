"""Decode a capture of the board's line into CSV: one row per frame, a column per field.

The capture is raw bytes, hex text or a logic analyser's export (--input raw, hex or
saleae-csv), decoded by `chassis.decode_capture` as `chassis decode` does. Without a file, it
records a few seconds of what the board sends (from --port, or from a simulated board it serves
itself) and decodes that:

    python capture_to_csv.py                          # record a simulated 2020 board
    python capture_to_csv.py --firmware v1.0.0 -o telemetry.csv
    python capture_to_csv.py capture.bin -o capture.csv
    python capture_to_csv.py export.csv --input saleae-csv

Only the standard library: the csv module writes the rows.
"""

from __future__ import annotations

import argparse
import contextlib
import csv
import json
import os
import select
import sys
import termios
import time
import tty
from typing import Any

import chassis


def record(path: str, seconds: float) -> bytes:
    """What comes in on serial port `path` for `seconds`, the port in raw mode at 115 200 bps."""
    fd = os.open(path, os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
    try:
        tty.setraw(fd)
        attrs = termios.tcgetattr(fd)
        attrs[4] = attrs[5] = termios.B115200  # input and output speed
        termios.tcsetattr(fd, termios.TCSANOW, attrs)
        chunks = []
        end = time.monotonic() + seconds
        while (left := end - time.monotonic()) > 0:
            if select.select([fd], [], [], left)[0]:
                chunks.append(os.read(fd, 4096))
        return b"".join(chunks)
    finally:
        os.close(fd)


def cell(value: Any) -> Any:
    """Lists (accel, gyro, ticks, …) as JSON text in one cell."""
    return json.dumps(value) if isinstance(value, (list, dict)) else value


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file", nargs="?", help="the capture (default: record one)")
    parser.add_argument("--input", default="raw", choices=["raw", "hex", "saleae-csv"])
    parser.add_argument("--firmware", choices=["2020", "v1.0.0"], help="default: detected")
    parser.add_argument("--port", help="record from this serial port (default: a simulated board)")
    parser.add_argument("--seconds", type=float, default=2.0, help="how long to record")
    parser.add_argument("-o", "--output", help="the CSV file (default: standard output)")
    args = parser.parse_args()

    if args.file is not None:
        with open(args.file, "rb") as f:
            data = f.read()
        decoded = chassis.decode_capture(data, input=args.input, firmware=args.firmware)
    else:
        with contextlib.ExitStack() as stack:
            port = args.port
            if port is None:
                port = stack.enter_context(chassis.sim.pty(args.firmware or "2020")).path
            data = record(port, args.seconds)
        print(f"recorded {len(data)} bytes in {args.seconds} s", file=sys.stderr)
        decoded = chassis.decode_capture(data, firmware=args.firmware)

    # The columns: every key of any frame, "frame" and "offset" first.
    keys = dict.fromkeys(key for frame in decoded for key in frame)
    columns: list[str] = [k for k in ("frame", "offset") if k in keys]
    columns += [k for k in keys if k not in columns]
    with contextlib.ExitStack() as stack:
        out = sys.stdout
        if args.output is not None:
            out = stack.enter_context(open(args.output, "w", newline=""))
        writer = csv.DictWriter(out, fieldnames=columns)
        writer.writeheader()
        for frame in decoded:
            writer.writerow({key: cell(value) for key, value in frame.items()})
    print(f"{len(decoded)} frames: {decoded.summary}", file=sys.stderr)


if __name__ == "__main__":
    main()
