"""2-Piece Assembly: a held piece into a square receptacle whose observed position is wrong until touched."""
