"""FSMs as transition tables: CSV and Markdown."""
