"""The shared numerical floor of both systems: the Dormand-Prince stepper and its
tableau, Newton shooting and Floquet multipliers on any period map, tolerances, integration
status codes, and the executor (serial, process pool, Dask) with its worker processes.
"""
