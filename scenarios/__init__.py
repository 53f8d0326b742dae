"""Built-in scenarios and bundled maps (installed as the package fleet.builtin_scenarios)."""
