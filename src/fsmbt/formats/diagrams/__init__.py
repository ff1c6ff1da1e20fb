"""Diagram languages: Graphviz DOT and Mermaid."""
