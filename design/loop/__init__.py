"""The design loop: what it is asked, how it searches and runs, its rounds, the choice of
the design to build and whether it fits the printer.

The names users need are on the design face (:mod:`holofold.design`)."""
