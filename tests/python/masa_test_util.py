"""What the Python module's tests share: PASS:/FAIL: lines (ctest matches them; an exception
anywhere prints FAIL: too) and skipping with a reason."""
import sys
import traceback


def run(main):
    try:
        failures = main()
    except SystemExit:
        raise
    except BaseException:
        traceback.print_exc()
        print("FAIL: an exception escaped the test")
        sys.exit(1)
    if failures:
        for f in failures:
            print(f"FAIL: {f}")
        sys.exit(1)
