"""The design report: one self-contained HTML page per build (``swiftfin report``, ``DIR/report.html``).

render  off-screen z-buffer pictures of triangle meshes (numpy + Pillow; no display, no OpenGL)
plots   the efficiency (paper Fig. 8 recomputed), tail-beat and body-wave plots, from physics/
html    the page: sections, tables, inlined images and styles (``write_report``)
"""
