"""What ``holofold design`` shows: the HTML report page, its 3D view, the distributions of
what the designs reach.

The names users need are on the design face (:mod:`holofold.design`)."""
