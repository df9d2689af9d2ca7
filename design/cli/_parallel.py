"""The ``--workers`` / ``--scheduler`` options shared by the commands that simulate designs."""

from __future__ import annotations

import argparse


def add_parallel_arguments(p: argparse.ArgumentParser) -> None:
    """Add ``--workers N`` (joblib processes) and ``--scheduler ADDRESS`` (Dask) to ``p``."""
    p.add_argument(
        "--workers",
        type=int,
        default=1,
        help=(
            "worker processes (default 1; -1 = every core); with --scheduler local the local "
            "cluster's processes (1 = every core), ignored with a remote --scheduler"
        ),
    )
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help=(
            "run on a Dask cluster at ADDRESS (e.g. tcp://host:8786), or 'local' for a local "
            "Dask cluster with --workers processes; needs the cluster extra "
            '(pip install "holofold[cluster]")'
        ),
    )
