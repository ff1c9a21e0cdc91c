"""The model: force laws (``law``, their grammar), candidate libraries
(``library``) and machine scenarios (``scenario``, the shipped ``scenarios/*.toml``).
"""
