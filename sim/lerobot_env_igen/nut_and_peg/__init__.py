"""Nut-and-Peg Assembly: the square nut picked up by its handle (maybe on the other side) and put on the peg."""
