# instruction counts of one build, rows given on the command line: PKG SIZE STEPS scene:integ ...
import sys
sys.path.insert(0, __import__("os").path.join(__import__("os").path.dirname(__file__), "../.."))
import cpu_speed_ab
pkg, size, steps = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
for row in sys.argv[4:]:
    scene, integ = row.rsplit(":", 1)
    print(pkg, scene, integ, size, steps, cpu_speed_ab.instructions(pkg, integ, scene, size, steps), flush=True)
