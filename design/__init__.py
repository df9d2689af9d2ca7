"""design layer of holofold."""
