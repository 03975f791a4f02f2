"""The README's compact benchmark table: one row per (map, N), one column per method.

Reads a benchmark's ``results.jsonl`` (or the folder holding it) and prints,
as Markdown, each method's success rate over every seed and fault setting
and the mean SoC/LB of its successful runs (``t/o``: every run hit the time
limit), then a line counting the runs by status and the runs with a collision.

Usage: python bench/compact_table.py DIR   (for example docs/bench/standard)
"""

from __future__ import annotations

import sys
from collections import Counter

from mrmp.bench.aggregate import compact_table, table_markdown
from mrmp.core.errors import InputError
from mrmp.io.report_input import read_bench_results


def main(arguments: list[str]) -> int:
    if len(arguments) != 1:
        print(__doc__.strip().splitlines()[-1], file=sys.stderr)
        return 2
    try:
        records = read_bench_results(arguments[0]).records
    except InputError as error:
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(table_markdown(compact_table(records)))
    statuses = Counter(record.status for record in records)
    successes = sum(1 for record in records if record.success)
    collided = sum(1 for record in records if record.collisions)
    counts = ", ".join(f"{count} {status}" for status, count in sorted(statuses.items()))
    print(f"\n{len(records)} runs: {counts}; {successes} with every robot on its goal; {collided} with a collision")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
