"""Run Klipper's host (klippy) in batch mode with a trace; a script for the referee's Python.

``python _klippy_batch.py TRACE PINS klippy-args...`` runs klippy's own ``main()`` with the
given arguments (``printer.cfg -i in.gcode -o out.serial -d mcu.dict -l klippy.log``) and

- writes to TRACE, one JSON list a line, what its planner receives (``LookAheadQueue.add_move``:
  end position and cruise speed) and its dwells;
- makes the end of the stream deterministic: batch mode ends by stopping the serial writer
  thread at once (``serialqueue_exit``), and the messages still queued then — the last pin
  changes, the steppers' disable — are lost when the machine is loaded. The writer is given
  the time to write every queued message first, and TRACE says how many bytes were still
  queued when it was stopped (the test asserts 0);
- decodes out.serial with klippy's own message parser and writes the digital-output messages
  (``config_digital_out``, ``queue_digital_out``) to PINS, in the order sent.

Test code of the rotomorph project, run by the referee; imports only klippy.
"""

import json
import math
import re
import sys
import time

import klippy.serialhdl as serialhdl
import klippy.toolhead as toolhead
from klippy import msgproto

log = open(sys.argv.pop(1), "w")  # open for the whole run
pins_path = sys.argv.pop(1)
args = sys.argv[1:]
serial_out, dictionary = args[args.index("-o") + 1], args[args.index("-d") + 1]

add_move = toolhead.LookAheadQueue.add_move


def traced_add_move(self, move):
    log.write(json.dumps(["move", list(move.end_pos), math.sqrt(move.max_cruise_v2)]) + "\n")
    return add_move(self, move)


toolhead.LookAheadQueue.add_move = traced_add_move
dwell = toolhead.ToolHead.dwell


def traced_dwell(self, delay):
    log.write(json.dumps(["dwell", delay]) + "\n")
    return dwell(self, delay)


toolhead.ToolHead.dwell = traced_dwell
disconnect = serialhdl.SerialReader.disconnect


def drained_disconnect(self):
    if self.serialqueue is not None:
        deadline = time.monotonic() + 60.0
        while True:
            stats = self.stats(time.monotonic())
            queued = sum(map(int, re.findall(r"(?:ready|upcoming)_bytes=(\d+)", stats)))
            if queued == 0 or time.monotonic() > deadline:
                break
            time.sleep(0.005)
        log.write(json.dumps(["queued_at_exit", queued]) + "\n")
    return disconnect(self)


serialhdl.SerialReader.disconnect = drained_disconnect

from klippy.printer import main  # noqa: E402 (after the patches above)

try:
    code = main()
except SystemExit as stop:  # klippy exits -1 after an error
    code = stop.code
log.close()

parser = msgproto.MessageParser()
with open(dictionary, "rb") as f:
    parser.process_identify(f.read(), decompress=False)
with open(serial_out, "rb") as f:
    data = bytearray(f.read())
messages = []
while data:
    size = parser.check_packet(data)
    if size == 0:
        break
    if size < 0:  # not a message block: skip as klippy's parsedump does
        data = data[-size:]
        continue
    messages += [m for m in parser.dump(data[:size])[1:] if "_digital_out " in m]
    data = data[size:]
with open(pins_path, "w") as f:
    f.write("\n".join(messages) + "\n")
sys.exit(code)
