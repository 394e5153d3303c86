#!/usr/bin/python3
"""Interoperability with Debian's python3-pymodbus (3.0), a Modbus stack nobody on the team wrote.

  interop_pymodbus.py server-tcp PORT      pymodbus serves the turntable register map
  interop_pymodbus.py server-rtu DEVICE    ... on a serial device (a socat pty), 19200 8N1, unit 1
  interop_pymodbus.py client-tcp PORT      pymodbus drives build/turntable-sim and checks it
  interop_pymodbus.py client-rtu DEVICE

8N1, not 8E1, on ptys: Linux pseudo-terminals refuse pyserial's re-configuration with parity
(EINVAL), and parity means nothing on a pty. The map is docs/turntable-modbus.md; the pymodbus controller moves instantly (no profile), which
is a second, different controller for the scanner's client to cope with."""
import sys
import time

from pymodbus.datastore import ModbusSequentialDataBlock, ModbusServerContext, ModbusSlaveContext

TARGET, ACTUAL, SPEED, ACCEL, COMMAND, COMMAND_ID, STATUS, ALARM, LAST_ID, DEVICE_ID = (
    0, 2, 4, 5, 6, 7, 8, 9, 10, 11)
WRITABLE = {0, 1, 4, 5, 6, 7}


def s32(hi, lo):
    v = (hi << 16) | lo
    return v - (1 << 32) if v & 0x80000000 else v


class Turntable(ModbusSequentialDataBlock):
    """The register map with the controller's behaviour behind it."""

    def __init__(self):
        super().__init__(0, [0] * 12)
        self.values[DEVICE_ID] = 0x5454
        self.values[SPEED], self.values[ACCEL] = 300, 600
        self.pos, self.homed, self.alarm, self.last = 12345, False, 0, 0
        self.refresh()

    def refresh(self):
        v = self.values
        p = self.pos & 0xFFFFFFFF
        v[ACTUAL], v[ACTUAL + 1] = p >> 16, p & 0xFFFF
        target = s32(v[TARGET], v[TARGET + 1])
        v[STATUS] = (2 if self.pos == target else 0) | (4 if self.homed else 0) | (
            8 if self.alarm else 0)
        v[ALARM], v[LAST_ID] = self.alarm, self.last

    def setValues(self, address, values):  # noqa: N802 (pymodbus's name)
        super().setValues(address, values)
        if address <= COMMAND_ID < address + len(values) and self.values[COMMAND_ID] != self.last:
            self.last = self.values[COMMAND_ID]
            cmd = self.values[COMMAND]
            if cmd == 1 and not self.alarm:
                if self.homed:
                    self.pos = s32(self.values[TARGET], self.values[TARGET + 1])
                else:
                    self.alarm = 2
            elif cmd == 2 and not self.alarm:
                self.pos, self.homed = 0, True
                self.values[TARGET], self.values[TARGET + 1] = 0, 0
            elif cmd == 4:
                self.alarm = 0
        self.refresh()


class Context(ModbusSlaveContext):
    def validate(self, fc_as_hex, address, count=1):
        if fc_as_hex in (6, 16) and any(a not in WRITABLE for a in range(address, address + count)):
            return False  # answered with exception 2, like the real controller
        return super().validate(fc_as_hex, address, count)


def serve(kind, where):
    from pymodbus.server import StartSerialServer, StartTcpServer
    from pymodbus.transaction import ModbusRtuFramer
    ctx = ModbusServerContext(slaves={1: Context(hr=Turntable(), zero_mode=True)}, single=False)
    if kind == "tcp":
        StartTcpServer(context=ctx, address=("127.0.0.1", int(where)))
    else:
        StartSerialServer(context=ctx, framer=ModbusRtuFramer, port=where, baudrate=19200,
                          parity="N", stopbits=1, bytesize=8)


def drive(kind, where):
    from pymodbus.client import ModbusSerialClient, ModbusTcpClient
    from pymodbus.transaction import ModbusRtuFramer
    if kind == "tcp":
        c = ModbusTcpClient("127.0.0.1", port=int(where), timeout=2)
    else:
        c = ModbusSerialClient(port=where, framer=ModbusRtuFramer, baudrate=19200, parity="N",
                               stopbits=1, bytesize=8, timeout=2)
    assert c.connect(), "cannot connect"

    def regs(addr, n):
        r = c.read_holding_registers(addr, n, slave=1)
        assert not r.isError(), r
        return r.registers

    def command(cmd, ident):
        assert not c.write_registers(COMMAND, [cmd, ident], slave=1).isError()

    def wait_idle():
        for _ in range(200):
            if not regs(STATUS, 1)[0] & 1:
                return
            time.sleep(0.05)
        raise AssertionError("still busy")

    assert regs(DEVICE_ID, 1) == [0x5454]
    assert not c.write_registers(SPEED, [1800, 7200], slave=1).isError()  # fast: 180 deg/s
    last = regs(LAST_ID, 1)[0]
    command(2, last + 1)  # home
    wait_idle()
    assert regs(STATUS, 1)[0] & 4, "not homed"
    target = 123456
    assert not c.write_registers(TARGET, [target >> 16, target & 0xFFFF], slave=1).isError()
    command(1, last + 2)
    wait_idle()
    a = regs(ACTUAL, 2)
    assert s32(a[0], a[1]) == target, s32(a[0], a[1])
    # the same COMMAND_ID again is a repeat: no motion
    other = 5000
    assert not c.write_registers(TARGET, [0, other], slave=1).isError()
    command(1, last + 2)
    time.sleep(0.2)
    a = regs(ACTUAL, 2)
    assert s32(a[0], a[1]) == target, "a repeated command id moved the table"
    # a read-only register refuses writes with exception 2
    r = c.write_registers(ACTUAL, [0, 0], slave=1)
    assert r.isError() and getattr(r, "exception_code", None) == 2, r
    c.close()
    print("pymodbus %s client: %s controller ok" % (kind, "build/turntable-sim"))


if __name__ == "__main__":
    mode, where = sys.argv[1], sys.argv[2]
    role, kind = mode.split("-")
    (serve if role == "server" else drive)(kind, where)
