"""The IR: what a grammar means, independent of the dialect it was written in.

``nodes`` defines the frozen node classes and the children each declares; ``traverse`` walks and rebuilds
any node from those declarations, ``functions`` types the built-in functions, and ``printer`` renders IR as canonical text. ``passes`` check,
transform and analyse a module, ``pipeline`` runs them in order and ``verify`` states what holds after
each. ``asset_names`` resolves the names of assets, for the passes and for whoever loads the files.
"""
