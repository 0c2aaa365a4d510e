"""One program under construction (native/src/scene/material_program.h): its registers,
constants, instructions and lookup tables (Builder), the values it computes (Val), and the
error a graph the programs cannot hold raises (Unsupported). Imports nothing of the add-on."""


REGS = 192          # kProgramRegs


class Unsupported(Exception):
    pass


class Val:
    """A value in the program: a constant tuple, or `width` registers from `reg`; `kind` is the
    Blender socket type it carries (VALUE, VECTOR, RGBA)."""

    __slots__ = ("const", "reg", "width", "kind")

    def __init__(self, const=None, reg=None, width=1, kind="VALUE"):
        self.const, self.reg, self.width, self.kind = const, reg, width, kind


class Builder:
    """Registers, constants and instructions of one program. Constants live in registers
    0..K-1 (preloaded), temporaries after them; while building, temporaries are numbered from
    TEMP and moved behind the constants by finish(). The registers of an instruction's input
    block are reused once it has run (release), which keeps long graphs within REGS."""

    TEMP = 4096

    def __init__(self):
        self.consts = []         # the preloaded registers
        self.ntemp = 0
        self.code = []           # [w0, w1, w2, w3]
        self.tables = []         # (instruction index, floats): appended after the constants
        self._consts = {}
        self._free = []          # [base, size] of spent input blocks

    def alloc(self, n):
        base = self._reuse(n)
        if base is not None:
            return base
        base = self.TEMP + self.ntemp
        self.ntemp += n
        if self.ntemp > REGS:
            raise Unsupported("the graph needs more registers than a program has")
        return base

    def _reuse(self, n):
        for i, (base, size) in enumerate(self._free):
            if size >= n:
                if size == n:
                    self._free.pop(i)
                else:
                    self._free[i] = [base + n, size - n]
                return base
        return None

    def release(self, base, n):
        self._free.append([base, n])

    def const(self, vals):
        vals = tuple(float(v) for v in vals)
        if vals not in self._consts:
            self._consts[vals] = len(self.consts)
            self.consts.extend(vals)
            if len(self.consts) > REGS:
                raise Unsupported("the graph has more constants than a program has registers")
        return self._consts[vals]

    def emit(self, op, mode=0, flags=0, dim=0, src=0, out=0, aux=0, aux2=0):
        self.code.append([op | (mode << 8) | (flags << 16) | (dim << 24), src, out,
                          aux & 0xFFFFFFFF, aux2 & 0xFFFFFFFF])
        return len(self.code) - 1

    def block(self, vals):
        """One contiguous block of temporaries holding vals (each of the width wanted):
        copies of constant registers and of values (the core folds the constant ones)."""
        n = sum(v.width for v in vals)
        base = self.alloc(n)
        at = base
        for v in vals:
            src = self.const(v.const) if v.const is not None else v.reg
            self.emit(0, dim=v.width, src=src, out=at)
            at += v.width
        return base

    def table(self, instr, floats):
        self.tables.append((instr, [float(x) for x in floats]))

    def finish(self, result, target):
        if result.const is not None:
            reg = self.const(result.const if result.width == 3 else result.const * 3)
        elif result.width == 1:
            reg = self.block([result, result, result])
        else:
            reg = result.reg
        k = len(self.consts)
        if k + self.ntemp > REGS:
            raise Unsupported("the graph needs more registers than a program has")

        def place(r):
            return k + (r - self.TEMP) if r >= self.TEMP else r
        code = [[w0, place(src) | (place(out) << 16), aux, aux2]
                for w0, src, out, aux, aux2 in self.code]
        consts = list(self.consts)
        for instr, floats in self.tables:
            code[instr][2] = len(consts)       # the table's offset in the program's constants
            consts.extend(floats)
        return {"target": target, "code": code, "consts": consts, "num_const": k,
                "result": place(reg)}
