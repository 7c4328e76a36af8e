"""APDL command families, one module per processor or topic.

Each module lists its commands in a `COMMANDS` tuple of `apdl_like.call.CommandSpec`
(plain data: name, processors, field count, handler).  `apdl_like.registry` imports the
families and builds the one name -> command table; nothing registers itself on import.
"""
