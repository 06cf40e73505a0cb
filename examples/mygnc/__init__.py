"""mygnc: a user's own blocks and plant for oceangnc (docs/developing.md, section 6).

Each module is one file with one compiled law: ``controller`` (a UUV controller), ``compass`` (a
sensor with noise and dropouts) and ``buoy`` (a plant). Register them with an entry point of the
group ``oceangnc.blocks`` (``mygnc = "mygnc.controller"`` ...) or ``--plugin`` one file.
"""
