#!/usr/bin/env python3
# inside unshare -m: hide the system's copies of everything in the bundle, then exec argv[2:]
import ctypes, os, sys, tempfile, glob
d = sys.argv[1]
libc = ctypes.CDLL("libc.so.6", use_errno=True)
MS_BIND = 4096
empty = tempfile.mkdtemp(); f = os.path.join(empty, "f"); open(f, "w").close()
def bind(src, dst):
    if libc.mount(src.encode(), dst.encode(), None, MS_BIND, None) != 0:
        raise OSError(ctypes.get_errno(), "mount " + dst)
for dir in ["/usr/lib/x86_64-linux-gnu/openmpi", "/usr/lib/x86_64-linux-gnu/pmix2", "/etc/openmpi", "/usr/share/openmpi"]:
    bind(empty, dir)
hidden = 0
for lib in glob.glob(d + "/lib/*"):
    p = "/lib/x86_64-linux-gnu/" + os.path.basename(lib)
    if os.path.exists(p):
        bind(f, os.path.realpath(p)); hidden += 1
bind(f, os.path.realpath("/usr/bin/orterun"))
print(f"hidden: the system's Open MPI, PMIx and {hidden} libraries", file=sys.stderr)
os.execvp(sys.argv[2], sys.argv[2:])
