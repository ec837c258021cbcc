"""Physical models of the bodies beyond the seed paper's half-space and flat layer.

Each module describes one aspect of a body as frozen, validated value objects
that the influence models read: :mod:`.shapes` the body's shape (the
half-space of today's model, or the finite cross-section of a cylinder, hollow
on a rigid shaft or covered on a rigid core).
"""
