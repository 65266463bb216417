"""The engines' trilith builders as they were before the body list
(:class:`engines.geometry.Structure`), kept verbatim so that a test can check the
worlds built from the body list are bit-identical to them.  Test code only."""
