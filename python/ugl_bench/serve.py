"""`python -m ugl_bench.serve LEARNER.pkl`: the external-learner program that `ugl_bench.compare`
hands to `ugl compare --command`. It loads the pickled learner object and speaks the protocol
for it (`ugl_bench.protocol.serve_object`, docs/external-learners.md)."""

import pickle
import sys


def main(argv):
    if len(argv) != 2:
        sys.exit("usage: python -m ugl_bench.serve LEARNER.pkl")
    try:
        with open(argv[1], "rb") as f:
            learner = pickle.load(f)
    except Exception as e:
        sys.exit(
            f"cannot load the learner from {argv[1]}: {type(e).__name__}: {e} (a class defined in a "
            "notebook or script needs cloudpickle: pip install cloudpickle)"
        )
    from .protocol import serve_object

    serve_object(learner)


if __name__ == "__main__":
    main(sys.argv)
