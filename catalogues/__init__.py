"""Bought things as tables (house style rule 15): fasteners, hinge pins and their clips, one TOML file each, with
their sources. Parts look sizes up (``fastener(3.0).insert_boss_od_mm(0.45)``) and never repeat loose numbers.

The lowest layer: it reads its own data files and imports nothing else of swiftfin (the parameter schema takes its
allowed sizes from here).
"""
