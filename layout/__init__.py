"""Kernel-free numbers from the parameters: stations, routes, spool dimensions, the parts' plans, loads."""
