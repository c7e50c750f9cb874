"""Nut Insertion: a held square nut onto a square peg whose observed position is wrong until touched."""
