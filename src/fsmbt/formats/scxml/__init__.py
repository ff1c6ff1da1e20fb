"""W3C SCXML: the structural reader and writer, the W3C algorithm and its data model, XInclude and <invoke> (docs/formats/scxml.md)."""
