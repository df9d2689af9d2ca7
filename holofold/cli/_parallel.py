"""The options shared by the commands that simulate designs: ``--workers`` / ``--scheduler``
and the per-row isolation ``--on-invalid`` / ``--row-timeout``."""

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


def add_row_arguments(p: argparse.ArgumentParser, on_invalid: str = "fail") -> None:
    """Add ``--on-invalid fail|skip`` (default ``on_invalid``) and ``--row-timeout S`` to
    ``p``: ``skip`` for commands that sample their own designs, whose refusals are rows of the
    database rather than a mistake in the user's input."""
    p.add_argument(
        "--on-invalid",
        choices=["fail", "skip"],
        default=on_invalid,
        help=(
            "a design that fails validation: 'fail' refuses the run before anything is "
            "simulated; 'skip' records it as a failed row with its reason and simulates the "
            f"others (default: {on_invalid})"
        ),
    )
    p.add_argument(
        "--row-timeout",
        metavar="S",
        default=None,
        help=(
            "time limit per design in seconds, past which the row is recorded as "
            "'failed: timeout ...' and the run goes on; 0 or none = no limit (default: the "
            "scenario's, 60 s for single-miura and arch, 300 s canopy, 120 s gripper)"
        ),
    )


def row_settings(args) -> tuple[str, float | None]:
    """(on_invalid, row_timeout) of parsed arguments: row_timeout None for the scenario's
    default, 0 for no limit, else seconds."""
    from holofold.design import resolve_row_timeout

    if args.row_timeout is None:
        return args.on_invalid, None
    try:
        limit = resolve_row_timeout(None, args.row_timeout)
    except ValueError:
        raise ValueError(
            f"--row-timeout {args.row_timeout}: must be seconds > 0, or 0 / none for no limit"
        ) from None
    return args.on_invalid, 0 if limit is None else limit
