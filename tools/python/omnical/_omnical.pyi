# Stub of the extension module omnical._omnical (written by hand; tests/python/test_stub.py
# checks it against the module).
