"""The two-body vibro-impact system of the first paper, in the order of its data
flow: ``model`` (force laws, libraries, scenarios) -> ``data`` (measurements, contact
samples, impulses) -> ``fit`` (certified sparse regression, discovery, identification)
-> ``dynamics`` (simulation to steady state) -> ``verify`` (criteria I0..I4, landscapes)
-> ``explain`` (the missing-effect workflow) and ``studies`` (model-term selection
studies).
"""
