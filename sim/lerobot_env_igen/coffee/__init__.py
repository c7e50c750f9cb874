"""Coffee: a held pod into a coffee machine's pod holder whose observed position is wrong until touched."""
