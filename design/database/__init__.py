"""Databases of simulated designs: sampling, validated evaluation (per-row status, time
limits, checkpoints) on processes or a Dask cluster, the resumable Parquet store, tables.

The names users need are on the design face (:mod:`holofold.design`)."""
