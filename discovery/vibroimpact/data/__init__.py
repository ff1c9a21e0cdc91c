"""The data layer: measured records (``measurement``), contact samples
(``samples``) and impulses (``impulse``). Nothing here simulates.
"""
