"""Learning an object outside the library: its model from the data components, written into a library.

Pure numpy and scipy (no simulator, no recording): :mod:`haptic.learning.reconstruct` makes the model,
:mod:`haptic.learning.boundary` any object's from its traced boundary, :mod:`haptic.learning.folds` says which
diagonals of its faces no move has crossed (a face folded along one is two), :mod:`haptic.learning.library` writes
it with its provenance.
"""
