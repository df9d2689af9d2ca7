"""holofold: holistic inverse design of origami, shape and function."""
