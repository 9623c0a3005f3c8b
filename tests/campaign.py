#!/usr/bin/env python3
"""An attacker's campaign against the cellmap command: damaged .cmdb files
(bytes flipped, rows changed in every table) given to every command that
reads or extends one. Every run must end with status 0, 1 or 2, without a
sanitizer report, and every file a command refuses (status 1) must be left
byte-identical.

usage: campaign.py CELLMAP RUNS [SEED]   (prints a summary; exit 1 on a finding)"""
import hashlib, os, random, shutil, sqlite3, subprocess, sys, tempfile

cm, runs = os.path.abspath(sys.argv[1]), int(sys.argv[2])
rng = random.Random(int(sys.argv[3]) if len(sys.argv) > 3 else 1)
work = tempfile.mkdtemp(prefix="cellmap-campaign-")
os.chdir(work)
env = dict(os.environ, ASAN_OPTIONS="detect_leaks=0", UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1")

def run(args, stdin=None):
    p = subprocess.run([cm] + args, input=stdin.encode() if stdin else None, capture_output=True,
                       env=env, timeout=300)
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

findings = 0
counts = {0: 0, 1: 0, 2: 0}
for k in range(runs):
    base = rng.choice(sorted(bases))
    path = "victim.cmdb"
    open(path, "wb").write(open(base, "rb").read())
    (damage_rows if rng.random() < 0.7 else damage_bytes)(path)
    before = sha(path)
    args, stdin = command(path, base)
    rc, err = run(args, stdin)
    bad = None
    if rc not in (0, 1, 2):
        bad = "exit status %d" % rc
    elif "Sanitizer" in err or "runtime error" in err:
        bad = "sanitizer report"
    elif rc == 1 and sha(path) != before and args[0] in ("info", "export", "render"):
        bad = "a read-only command changed the file"
    elif rc == 1 and "damaged" in err and sha(path) != before:
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
