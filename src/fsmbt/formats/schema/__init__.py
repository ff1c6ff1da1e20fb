"""fsmbt's own schema (docs/formats/json.md), as JSON and as YAML."""
