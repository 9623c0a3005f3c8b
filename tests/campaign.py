#!/usr/bin/env python3
"""An attacker's campaign against the cellmap command. Half the runs give
damaged .cmdb files (bytes flipped, rows changed in every table) to every
command that reads or extends one; the other half attack the other
surfaces with a healthy file: export windows (thin, huge, reversed, not a
number), palette and labels files (random bytes, devices, directories,
FIFOs, huge lines), explore scripts, and mutated command lines of every
analysis command (values swapped for extreme ones, options dropped,
doubled or misspelt). Every run must end within its time-out with status
0, 1, 2 or 130, without a sanitizer report; every input a command reads
(the database, palette, labels and script files) must be left
byte-identical when the command only reads it or refuses it, and no
temporary output file (OUT.tmp-PID) may be left behind.

usage: campaign.py CELLMAP RUNS [SEED]   (prints a summary; exit 1 on a finding)"""
import hashlib, os, random, shutil, sqlite3, subprocess, sys, tempfile

cm, runs = os.path.abspath(sys.argv[1]), int(sys.argv[2])
rng = random.Random(int(sys.argv[3]) if len(sys.argv) > 3 else 1)
work = tempfile.mkdtemp(prefix="cellmap-campaign-")
os.chdir(work)
env = dict(os.environ, ASAN_OPTIONS="detect_leaks=0", UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1")

HANG = -1000   # the status of a run that did not end within its time-out

def run(args, stdin=None, timeout=300):
    try:
        p = subprocess.run([cm] + args, input=stdin.encode() if stdin else None, capture_output=True,
                           env=env, timeout=timeout)
    except subprocess.TimeoutExpired:
        return HANG, "no end within %d s" % timeout
    return p.returncode, p.stderr.decode(errors="replace")

split = "--cells 60x40 --split 3x2 --threads 2".split()
bases = {"split.cmdb": ["solve"] + split + ["--db", "split.cmdb"],
         "one.cmdb": ["solve", "--cells", "50x30", "--db", "one.cmdb"]}
for name, args in bases.items():
    assert run(args)[0] == 0, name
assert run(["explore", "explore.cmdb", "-", "--model", "microchaos-pd", "--cell-size", "5,1"],
           "view 0:100 -20:20\npan right 30%\n")[0] == 0
bases["explore.cmdb"] = None

def sha(path):
    return hashlib.sha256(open(path, "rb").read()).hexdigest()

def weird_value():
    kind = rng.randrange(8)
    if kind == 0: return rng.choice([0, -1, 1, 2**31, 2**32 + 5, 2**63 - 1, -2**63, 70000])
    if kind == 1: return rng.choice([float("nan"), float("inf"), -1e300, 1e-320, 0.5])
    if kind == 2: return rng.choice(["", "[", "[1e308,0]", "[0,0]", "[NaN,1]", "x" * 3000, "[1,2,3,4,5,6,7]", "{}"])
    if kind == 3: return bytes(rng.randrange(256) for _ in range(rng.randrange(64)))
    if kind == 4: return None
    return rng.randrange(-5, 500)

def damage_rows(path):
    db = sqlite3.connect(path)
    tables = [r[0] for r in db.execute("SELECT name FROM sqlite_master WHERE type='table'")]
    for _ in range(rng.randrange(1, 4)):
        t = rng.choice(tables)
        cols = [r[1] for r in db.execute("PRAGMA table_info(%s)" % t)]
        rows = [r[0] for r in db.execute("SELECT rowid FROM %s" % t)]
        if not rows:
            continue
        what = rng.randrange(10)
        try:
            if what == 0:
                db.execute("DELETE FROM %s WHERE rowid = ?" % t, (rng.choice(rows),))
            elif what == 1 and t in ("pages", "nodes", "exits", "open_nodes"):   # swap two BLOBs
                c = rng.choice([c for c in cols if c in ("image", "grp", "step", "data", "targets")])
                a, b = rng.choice(rows), rng.choice(rows)
                va = db.execute("SELECT %s FROM %s WHERE rowid=?" % (c, t), (a,)).fetchone()[0]
                vb = db.execute("SELECT %s FROM %s WHERE rowid=?" % (c, t), (b,)).fetchone()[0]
                db.execute("UPDATE %s SET %s=? WHERE rowid=?" % (t, c), (vb, a))
                db.execute("UPDATE %s SET %s=? WHERE rowid=?" % (t, c), (va, b))
            else:
                db.execute('UPDATE %s SET "%s" = ? WHERE rowid = ?' % (t, rng.choice(cols)),
                           (weird_value(), rng.choice(rows)))
        except sqlite3.Error:
            pass
    db.commit()
    db.close()

def damage_bytes(path):
    data = bytearray(open(path, "rb").read())
    for _ in range(rng.randrange(1, 20)):
        i = rng.randrange(100 if rng.random() < 0.1 else len(data))
        data[i] = rng.randrange(256)
    if rng.random() < 0.1:
        data = data[:rng.randrange(len(data))]
    open(path, "wb").write(bytes(data))

def command(path, base):
    c = rng.randrange(8)
    if c == 0: return ["info", path], None
    if c == 1: return ["export", path, "--cells", "c.csv", "--groups", "g.csv"], None
    if c == 2: return ["export", path, "--flat", "f.sqlite", "--mem", "1M"], None
    if c == 3: return ["render", path, "--png", "r.png", "--layers", "all", "--size", "300x200"], None
    if c == 4: return ["render", path, "--png", "r.png", "--png-mode", "indexed"], None
    if c == 5 and base == "split.cmdb": return ["solve"] + split + ["--db", path, "--resume"], None
    script = "stats\npan left 20%\nrender e.png 200x150 --layers all\nstats\nzoom 0.5\n"
    return ["explore", path, "-", "--mem", "1M"], script

# --- the other surfaces, with healthy files ------------------------------------
os.mkfifo("fifo")
os.mkdir("adir")
def weird_number():
    return rng.choice(["0", "-1", "1e308", "-1e308", "nan", "inf", "-inf", "1e-320", "2147483648",
                       "9223372036854775807", "-9223372036854775808", "18446744073709551616",
                       "0x10", "1,2", "", " ", "1:2", "3.5", "100000", "1e9", "7", "0.5", "-0.0"])

def weird_window():
    def rng_text():
        a, b = sorted([rng.choice([-1e12, -500, -40, -1, 0, 1e-9, 0.3, 1, 1.01, 1.5, 40, 250, 500, 1e12]) for _ in range(2)])
        if rng.random() < 0.15: a, b = b, a
        if rng.random() < 0.1: return weird_number() + ":" + weird_number()
        return "%r:%r" % (a, b)
    dims = rng.choice([2, 2, 2, 1, 3])
    return ",".join(rng_text() for _ in range(dims))

def user_file():
    """A palette or labels file: random bytes, lines, or a device / FIFO / directory."""
    k = rng.randrange(8)
    if k == 0: return rng.choice(["/dev/zero", "/dev/null", "fifo", "adir", "missing.txt", "split.cmdb"])
    with open("u.txt", "wb") as f:
        if k == 1: f.write(bytes(rng.randrange(256) for _ in range(rng.randrange(1, 4000))))
        elif k == 2: f.write(b"#" + b"f" * rng.randrange(1, 100000) + b"\n")
        elif k == 3: f.write(b"".join(b"%d %s\n" % (rng.randrange(-3, 70000), bytes(rng.randrange(32, 127) for _ in range(rng.randrange(0, 300)))) for _ in range(rng.randrange(1, 300))))
        elif k == 4: f.write(b"".join(b"#%06x\n" % rng.randrange(1 << 24) for _ in range(rng.randrange(0, 3000))))
        else: f.write(b"".join(rng.choice([b"#12345\n", b"#gggggg\n", b"1,2 a\n", b"0 x\n", b"\x00\n", b"\n", b"#ffffff\r\n", b"2147483648 y\n"]) for _ in range(rng.randrange(1, 50))))
    return "u.txt"

ANALYSIS = [
    ["sweep", "--vary", "P=0.006,0.007", "--cells", "40x20", "--csv", "o.csv"],
    ["orbit", "--from", "10,0", "--steps", "3", "--csv", "o.csv"],
    ["fixed-points", "--range", "0:2", "--csv", "o.csv"],
    ["lyapunov", "--param", "S0=0.4", "--grid", "Omega=0.49:0.51:2,S=0.3:0.5:2", "--periods", "5", "--csv", "o.csv"],
    ["simulate", "--param", "S=0.4,S0=0.4,Omega=0.5", "--periods", "2", "--csv", "o.csv"],
    ["bifurcation", "--param", "S0=0.4,Omega=0.5", "--sweep", "S=0.32,0.4", "--transient", "5", "--record", "2", "--csv", "o.csv"],
    ["continue", "--param", "S=0.3,S0=0.4,Omega=0.5", "--vary", "S=0.3:0.32", "--down", "--csv", "o.csv"],
    ["amplitude", "--param", "S=0.5,S0=0.5", "--omega", "0.1:3:30", "--csv", "o.csv"],
    ["escape", "--param", "b=1.3", "--I0", "0.25", "--sweep", "a=1.3:1.5:2", "--cells", "1000", "--ensemble", "1000", "--csv", "o.csv"],
    ["stability", "--param", "alpha=0.8,beta=0.3,P=0.9,D=0.4", "--P", "0.65:1.5:20", "--csv", "o.csv"],
    ["horseshoe", "--param", "alpha=0.77,beta=0.02,D=0.83", "--m", "3:3", "--sweep", "P=0.65:0.72:5", "--periods", "8", "--csv", "o.csv"],
    ["partition", "--param", "a=1.3,b=0.66", "--csv", "o.csv"],
    ["solve", "--cells", "40x30", "--attractor-steps", "16,100", "--outside-steps", "20", "--json"],
]

def mutated(line):
    """A command line with one to three mutations: a value made extreme, an
    option dropped or doubled, a stray or misspelt word."""
    args = list(line)
    for _ in range(rng.choice([0, 1, 1, 1, 1, 2, 2, 3])):
        k = rng.randrange(6)
        values = [i for i, a in enumerate(args) if i > 0 and not a.startswith("--")]
        if k <= 1 and values:
            i = rng.choice(values)
            if "=" in args[i]:
                name = args[i].split("=")[0]
                args[i] = name + "=" + rng.choice([weird_number(), weird_number() + ":" + weird_number(),
                                                   weird_number() + ":" + weird_number() + ":" + weird_number()])
            else:
                args[i] = rng.choice([weird_number(), weird_window()])
        elif k == 2 and len(args) > 2:
            del args[rng.randrange(1, len(args))]
        elif k == 3:
            i = rng.randrange(1, len(args))
            args[i:i] = args[i:i + 2]
        elif k == 4:
            args.insert(rng.randrange(1, len(args) + 1), rng.choice(["stray", "--stray", "-", "--", "--csv", "--threads=0", "--quiet"]))
        else:
            args += rng.choice([["--csv", "-"], ["--csv", "adir"], ["--csv", "nodir/o.csv"], ["--json"], ["--threads", weird_number()]])
    return args

SCRIPT_LINES = ["view 0:100 -20:20", "pan left 20%", "pan right 30%", "pan up 100c", "zoom 0.5", "zoom 2",
                "goto 50,0", "extend auto 2", "stats", "stats --json", "render e.png 120x90 --layers all",
                "export --cells e.csv", "save", "view 1e300:1e301 0:1", "zoom 1e-300", "pan left 1e9c",
                "render u.txt", "export --flat script.cmdb", "extend auto 1001", "view nan:1 0:1", "help"]

def other_surface():
    """One run on a healthy file: (args, stdin, timeout, files it must leave alone)."""
    k = rng.randrange(5)
    if k == 0:
        out = rng.choice([["--labels", "L.npy"], ["--steps", "S.npy"], ["--cells", "c.csv"], ["--flat", "f.sqlite"],
                          ["--labels", "x.npy", "--steps", "x.npy"], ["--groups", "g.csv", "--cells", "c.npy"]])
        return ["export", "split.cmdb"] + out + ["--window", weird_window()], None, 120, ["split.cmdb"]
    if k == 1:
        u = user_file()
        opt = rng.choice(["--palette", "--labels"])
        cmd = rng.choice([["render", "split.cmdb", "--png", "r.png", "--size", "300x200"],
                          ["export", "split.cmdb", "--labels", "L.npy"] if opt == "--palette" else ["render", "split.cmdb", "--png", "r.png"],
                          ["solve", "--cells", "40x30", "--png", "r.png"]])
        return cmd + [opt, u], None, 60, ["split.cmdb"] + ([u] if os.path.isfile(u) else [])
    if k == 2:
        lines = [rng.choice(SCRIPT_LINES) for _ in range(rng.randrange(1, 8))]
        if rng.random() < 0.8:
            lines.insert(0, "view 0:100 -20:20")
        return ["explore", "script.cmdb", "-", "--model", "microchaos-pd", "--cell-size", "5,1"], "\n".join(lines) + "\n", 120, ["split.cmdb"]
    return mutated(rng.choice(ANALYSIS)), None, 120, ["split.cmdb"]

def clean_outputs():
    for f in os.listdir("."):
        if f not in ("split.cmdb", "one.cmdb", "explore.cmdb", "fifo", "adir") and os.path.isfile(f) and not f.startswith("finding-"):
            os.remove(f)

findings = 0
counts = {0: 0, 1: 0, 2: 0}
def found(bad, args, err):
    global findings
    findings += 1
    print("FINDING %s: cellmap %s\n%s" % (bad, " ".join(args), err[-2000:]))

for k in range(runs):
    if k % 2:
        args, stdin, timeout, inputs = other_surface()
        sums = {f: sha(f) for f in inputs if os.path.isfile(f)}
        rc, err = run(args, stdin, timeout)
        if os.environ.get("CAMPAIGN_VERBOSE"): print(rc, " ".join(args), "|", err.strip().splitlines()[-1:] if err.strip() else "")
        if rc not in (0, 1, 2, 130):
            found("exit status %d" % rc if rc != HANG else "a hang", args, err)
        elif "Sanitizer" in err or "runtime error" in err:
            found("sanitizer report", args, err)
        elif any(sha(f) != s for f, s in sums.items() if os.path.isfile(f)):
            found("an input was changed: %s" % [f for f, s in sums.items() if sha(f) != s], args, err)
        elif any(".tmp-" in f for f in os.listdir(".")):
            found("a temporary file was left: %s" % [f for f in os.listdir(".") if ".tmp-" in f], args, err)
        counts[rc] = counts.get(rc, 0) + 1
        clean_outputs()
        if os.path.exists("script.cmdb"): os.remove("script.cmdb")
        continue
    base = rng.choice(sorted(bases))
    path = "victim.cmdb"
    open(path, "wb").write(open(base, "rb").read())
    (damage_rows if rng.random() < 0.7 else damage_bytes)(path)
    before = sha(path)
    args, stdin = command(path, base)
    rc, err = run(args, stdin)
    bad = None
    if rc not in (0, 1, 2):
        bad = "exit status %d" % rc if rc != HANG else "a hang"
    elif "Sanitizer" in err or "runtime error" in err:
        bad = "sanitizer report"
    elif rc in (1, 2) and sha(path) != before and args[0] in ("info", "export", "render"):
        bad = "a read-only command changed the file"
    elif rc in (1, 2) and sha(path) != before and ("damaged" in err or "not a cellmap database" in err):
        bad = "a refused file was changed"
    if bad:
        findings += 1
        keep = "finding-%d.cmdb" % findings
        open(keep, "wb").write(open(base, "rb").read())
        print("FINDING %s: cellmap %s (base %s)\n%s" % (bad, " ".join(args), base, err[-2000:]))
        os.rename(path, keep)
    counts[rc] = counts.get(rc, 0) + 1
    for f in ("victim.cmdb-wal", "victim.cmdb-shm", "victim.cmdb-journal"):
        if os.path.exists(f): os.remove(f)
print("campaign: %d runs, exit statuses %s, %d findings%s" %
      (runs, counts, findings, " (the files are in %s)" % work if findings else ""))
if not findings:
    shutil.rmtree(work)
sys.exit(1 if findings else 0)
