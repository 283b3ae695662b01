"""The IR: what a grammar means, independent of the dialect it was written in.

``nodes`` defines the frozen node classes, ``verify`` states and checks what holds after lowering,
``passes`` transform a module, ``pipeline`` runs them in order, ``printer`` renders IR as canonical text.
"""
