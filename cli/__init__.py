"""adhesive_contact_cli: the ``adhcontact`` command line (docs/outputs.md).

A thin layer over :mod:`adhesive_contact`: :mod:`.main` parses arguments,
reads the scene, calls the library and reports errors in one line;
:mod:`.summary` formats the records of ``summary.json`` (the quantities
come from :mod:`adhesive_contact.postprocess`);
:mod:`.output` writes the output folder (JSON, NPZ, XDMF) atomically, its
PNG figures drawn by :mod:`adhesive_contact.visuals`. No module here imports
matplotlib: :mod:`.main` selects its Agg backend when a command runs.
"""
