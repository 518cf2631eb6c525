

DESIGN_HELP = "parameter file (default: ./swiftfin.toml if there is one, else the SwiftFin design shipped with swiftfin)"
