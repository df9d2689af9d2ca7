"""geometry layer of holofold."""
