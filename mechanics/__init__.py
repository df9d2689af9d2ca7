"""mechanics layer of holofold."""
