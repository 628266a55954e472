#!/usr/bin/env python3
"""soak_check.py STATE RECORD LEDGER [--final] - one round of the soak's invariants
(tests/fault/soak.sh) on the live database of a running server, read-only (a WAL reader, in one
read transaction, so it sees one committed state):

  - no job in two states: each job's events form one path (one creation event, each event leaves
    from the state the one before it left the job in, nothing after a terminal state) that ends
    in the job's state;
  - no two live attempts: the attempts of a job's claims (queued -> running) rise, and a claim
    comes only from queued, so an attempt is live only until the next event leaves running;
  - no stale result: no file or log chunk of an attempt after the job's last; a succeeded job
    has one succeeded event, of its final attempt, and that attempt's result.h5 is indexed and on
    disk at its size;
  - every key poro-load recorded as acknowledged (200/201) names one job, the one it was told;
  - a failed job says why (a message).

Jobs that ended, were checked and whose key poro-load has recorded as acknowledged go into LEDGER
(JSON: job id -> outcome, key) and are printed, one id a line, for soak.sh to delete (deletion
frees their files, so 10,000 jobs fit on the disk; a deleted job's key is not retried, since its
acknowledgement was recorded). Problems go to stderr as "problem: ..." and make the exit status 1.
With --final: every acknowledged key must be in LEDGER or the database with a terminal job, and
one summary line is printed: "jobs N: succeeded S, failed F (reasons: ...), attempts ...".
"""
import collections, json, os, sqlite3, sys

state, record, ledger_path = sys.argv[1:4]
final = "--final" in sys.argv
problems = []
def problem(text):
    problems.append(text)

ledger = json.load(open(ledger_path)) if os.path.exists(ledger_path) else {}
acked = {}
if os.path.exists(record):
    for line in open(record):
        p = line.split()
        if len(p) == 3 and p[1] in ("200", "201") and p[2] != "-":
            acked.setdefault(p[0], set()).add(int(p[2]))
for key, ids in acked.items():
    if len(ids) != 1:
        problem("key %s acknowledged as jobs %s" % (key, sorted(ids)))

db = sqlite3.connect("file:%s/poro.db?mode=ro" % state, uri=True, isolation_level=None, timeout=30)
db.execute("BEGIN")
jobs = {j: (s, a, m) for j, s, a, m in db.execute("SELECT id, state, attempt, message FROM jobs")}
keys = {k: j for k, j in db.execute("SELECT key, job_id FROM idempotency")}
events = collections.defaultdict(list)
for j, frm, to, attempt in db.execute("SELECT job_id, from_state, to_state, attempt FROM events ORDER BY id"):
    events[j].append((frm, to, attempt))
files = collections.defaultdict(list)
for j, attempt, name, size in db.execute("SELECT job_id, attempt, name, size FROM files"):
    files[j].append((attempt, name, size))
late_logs = list(db.execute("SELECT l.job_id, l.attempt FROM log_attempts l JOIN jobs j ON j.id = l.job_id"
                            " WHERE l.attempt > j.attempt"))
db.execute("COMMIT")

TERMINAL = ("succeeded", "failed", "cancelled")
for j, (st, attempt, message) in jobs.items():
    ev = events.get(j, [])
    if not ev or ev[0][0] is not None or ev[0][1] != "queued":
        problem("job %d does not begin with its creation event" % j)
        continue
    claims = [e[2] for e in ev if e[0] == "queued" and e[1] == "running"]
    if claims != sorted(set(claims)):
        problem("job %d: claims of attempts %s do not rise" % (j, claims))
    for prev, cur in zip(ev, ev[1:]):
        if cur[0] is None:
            problem("job %d has a second creation event" % j)
        elif cur[0] != prev[1]:
            problem("job %d: event %s->%s after one that left it %s" % (j, cur[0], cur[1], prev[1]))
        if prev[1] in TERMINAL:
            problem("job %d: event after its end (%s)" % (j, prev[1]))
    if ev[-1][1] != st:
        problem("job %d is %s but its events left it %s" % (j, st, ev[-1][1]))
    for a, name, size in files.get(j, []):
        if a > attempt:
            problem("job %d: file '%s' of attempt %d after its last (%d)" % (j, name, a, attempt))
        # a running job's file may be replaced by a newer version (result.h5 grows at each
        # checkpoint) between this read and the stat below: its size is checked once it ended
        path = os.path.join(state, "files", str(j), str(a), name)
        if not os.path.isfile(path) or st in TERMINAL and os.path.getsize(path) != size:
            problem("job %d: indexed file %s is not on disk at %d bytes" % (j, path, size))
    if st == "succeeded":
        wins = [e for e in ev if e[1] == "succeeded"]
        if len(wins) != 1 or wins[0][2] != attempt:
            problem("job %d: succeeded events %s, final attempt %d" % (j, wins, attempt))
        if not any(a == attempt and n == "result.h5" for a, n, s in files.get(j, [])):
            problem("job %d succeeded without a result.h5 of attempt %d" % (j, attempt))
    if st == "failed" and not (message or "").strip():
        problem("job %d failed without a reason" % j)
for j, a in late_logs:
    problem("job %d: log of attempt %d after its last" % (j, a))

key_of = {j: k for k, j in keys.items()}
for key, ids in acked.items():
    j = min(ids)
    if str(j) in ledger:
        if ledger[str(j)]["key"] != key:
            problem("key %s acknowledged as job %d, which was checked under key %s" % (key, j, ledger[str(j)]["key"]))
    elif keys.get(key) != j:
        problem("key %s acknowledged as job %d, stored as %s" % (key, j, keys.get(key)))

# ended, checked and acknowledged: into the ledger, to be deleted
done = []
if not problems:
    for j, (st, attempt, message) in jobs.items():
        key = key_of.get(j)
        if st in TERMINAL and key in acked and acked[key] == {j}:
            ledger[str(j)] = {"key": key, "state": st, "attempt": attempt, "message": message or ""}
            done.append(j)
    tmp = ledger_path + ".tmp"
    json.dump(ledger, open(tmp, "w"))
    os.replace(tmp, ledger_path)
for p in problems[:20]:
    print("problem: " + p, file=sys.stderr)
if final:
    open_jobs = [j for j, (st, a, m) in jobs.items() if st not in TERMINAL]
    if open_jobs:
        print("problem: %d jobs have not ended: %s" % (len(open_jobs), open_jobs[:10]), file=sys.stderr)
        problems.append("open jobs")
    outcomes = collections.Counter(v["state"] for v in ledger.values())
    reasons = collections.Counter(v["message"].split(":")[0][:40] for v in ledger.values() if v["state"] == "failed")
    attempts = collections.Counter(v["attempt"] for v in ledger.values())
    print("jobs %d: succeeded %d, failed %d%s, cancelled %d; attempts per job %s" % (
        len(ledger), outcomes["succeeded"], outcomes["failed"],
        " (%s)" % ", ".join("%s: %d" % kv for kv in reasons.most_common(4)) if reasons else "",
        outcomes["cancelled"], ", ".join("%d: %d" % kv for kv in sorted(attempts.items()))))
else:
    for j in done:
        print(j)
sys.exit(1 if problems else 0)
