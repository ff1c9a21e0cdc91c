"""The data layer: measured records (``measurement``), contact samples
(``samples``) and impulses (``impulse``, over ``contact_edges``: a force record's
contacts, ``periods``: its own and its drive periods, and ``noise``). Nothing here
simulates.
"""
