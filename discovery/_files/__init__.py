"""Files in and out, private to the package: numeric CSV records read (``_csv``), JSON values
and documents (``_jsonable``), atomic result directories (``_io``, over ``_staging``: the names
a run owns while it writes, atomic writes; ``_ownership``: the command a result belongs to,
manifests; ``_output_checks``: an output path refused before any work; ``_handoff``: files
written by forked children while the command goes on; ``_drawer``: the figures drawn by a
process forked when the command starts), the provenance a
result records (``_provenance``), and paths shortened for one-line messages (``_text``).

Imports nothing itself: each module is imported by its path."""
