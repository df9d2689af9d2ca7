"""The ``--workers`` / ``--scheduler`` options shared by the commands that simulate designs."""

from __future__ import annotations

import argparse


def add_parallel_arguments(p: argparse.ArgumentParser) -> None:
    """Add ``--workers N`` (joblib processes) and ``--scheduler ADDRESS`` (Dask) to ``p``."""
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help=(
            "worker processes (default 1; -1 = every core); with --scheduler local the local "
            "cluster's processes (default: one per core); not allowed with a remote --scheduler, "
            "whose cluster has its own workers"
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


def parallel_settings(args) -> tuple[int, str | None]:
    """(workers, scheduler) of parsed arguments, checked before anything is written."""
    from holofold.design import check_scheduler, check_workers  # the runner imports pandas

    scheduler = None if args.scheduler is None else check_scheduler(args.scheduler)
    if args.workers is None:
        return (-1 if scheduler == "local" else 1), scheduler
    if scheduler not in (None, "local"):
        raise ValueError(
            f"--workers {args.workers}: the Dask cluster at {scheduler} has its own workers; "
            "use --workers with joblib or --scheduler local"
        )
    try:
        return check_workers(args.workers), scheduler
    except ValueError:
        raise ValueError(f"--workers {args.workers}: must be >= 1 or -1 (every core)") from None
