"""Reading grammar text: UTF-8 with or without a BOM, else Windows-1252 with a warning."""

from grammarc.compiler import compile_grammar
from grammarc.frontend.source import decode_grammar, read_grammar_text


def test_utf8_with_and_without_a_bom():
    assert decode_grammar("// façade\n".encode()) == ("// façade\n", None)
    assert decode_grammar(b"\xef\xbb\xbf// fa\xc3\xa7ade\n") == ("// façade\n", None)


def test_windows_1252_is_the_fallback_and_keeps_the_lines():
    text, fallback = decode_grammar("// façade – € \n// étage\nLot --> X.\n".encode("cp1252"))
    assert (text, fallback) == ("// façade – € \n// étage\nLot --> X.\n", "cp1252")
    assert decode_grammar(b"// \x81\x8d\n")[0] == "// \ufffd\ufffd\n"  # bytes cp1252 leaves unassigned


def test_the_main_grammar_file_in_windows_1252_and_with_a_bom(tmp_path):
    """A BOM was a syntax error; a Latin-1 comment made `cannot read grammar`."""
    latin = tmp_path / "latin.cga"
    latin.write_bytes('version "2019.0"\n// Fa\xe7ade\n@StartRule\nLot --> extrude(3) Mass.\n'.encode("latin-1"))
    grammar = compile_grammar(latin)
    [(code, message, line)] = [(w.code, w.message, w.span.line) for w in grammar.warnings]
    assert (code, line) == ("encoding", 1) and f"`{latin}` is not UTF-8" in message
    bom = tmp_path / "bom.cga"
    bom.write_bytes(b'\xef\xbb\xbfversion "2019.0"\n@StartRule\nLot --> extrude(3) Mass.\n')
    assert compile_grammar(bom).warnings == ()
    assert read_grammar_text(bom)[0].startswith("version")
