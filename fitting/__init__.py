"""fitting layer of holofold."""
