"""The generated ``bushing_messages.h``: the runtime policy's words (``fmi.runtime_messages``) as
C macros, so the native FMU logs what the pythonfmu slave logs."""
from __future__ import annotations

from ..runtime_messages import INPUTS, MESSAGES, TEXTS, Message
from .generate import c_string

C_LEVELS = {"error": ("BW_ERROR", "logStatusError"), "warning": ("BW_WARNING", "logStatusWarning"),
            "refusal": ("BW_DISCARD", "logStatusError")}
"""Each message level's status and log category in C (``bw_log``)."""


def c_header() -> str:
    """``bushing_messages.h``: each message a macro over ``bw_log`` (``bw_refuse`` for a refusal,
    which returns ``BW_DISCARD``), the fixed words and the inputs' format as string constants."""
    lines = ["/* Generated from fmu_src/fmi/runtime_messages.py: the runtime policy's words, defined once. */",
             "#ifndef BUSHING_MESSAGES_H", "#define BUSHING_MESSAGES_H", ""]
    for name, text in TEXTS.items():
        lines.append(f"#define BW_TEXT_{name} {c_string(text)}")
    inputs, order = Message("error", INPUTS).c_format()
    lines += ["", f"/* arguments: {', '.join(order)} */", f"#define BW_TEXT_INPUTS {c_string(inputs)}", ""]
    for name, message in MESSAGES.items():
        format_, arguments = message.c_format()
        parameters = ", ".join(("inst",) + message.fields)
        passed = "".join(f", ({argument})" for argument in arguments)
        if message.level == "refusal":
            call = f"bw_refuse(inst, {c_string(format_)}{passed})"
        else:
            status, category = C_LEVELS[message.level]
            call = f"bw_log(inst, {status}, {c_string(category)}, {c_string(format_)}{passed})"
        lines.append(f"#define BW_MESSAGE_{name}({parameters}) {call}")
    lines += ["", "#endif", ""]
    return "\n".join(lines)
