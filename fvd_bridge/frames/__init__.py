"""Structures for the frame examples and their ground motions (``frames.motions``)."""
