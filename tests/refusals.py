"""The refusal cases of issues 15 and 36 (the audits of c8fe4cc): one list, each case run once, where its
setting is. tests/test_hardening.py runs the cases that need no file, in-process in an empty folder (and checks
nothing was written); tests/test_fuzz.py runs the cases that name one of its hostile files (``@name``, made in
its sandbox). Each case: (argv, a needle of the one ``Error:`` line)."""

REFUSED_IN_ONE_LINE = [
    (["min-contact", "--e1", "35000", "--e2", "20000", "--exact", "--table", "svm-paper"], "contradict"),
    (["max-noise", "--e1", "35000", "--e2", "20000", "--contact", "2", "--exact", "--table", "svm-paper"],
     "contradict"),
    (["min-delta-t", "--e1", "35000", "--e2", "20000", "--contact", "2", "--exact", "--table", "svm-paper"],
     "contradict"),
    (["delta-e", "--e", "35000", "--contact", "2", "--exact", "--table", "svm-paper"], "contradict"),
    (["distinguishable", "--e1", "35000", "--e2", "20000", "--contact", "2", "--exact", "--table", "svm-paper"],
     "contradict"),
    (["matrix", "--m", "copper", "--m", "glass", "--set", "paper12"], "contradict"),
    (["matrix", "--m", "copper", "--m", "glass", "--from", "-"], "contradict"),
    (["classify", "--m", "wood", "--m", "copper", "--port", "/dev/null", "--export-c", "x.h"], "contradict"),
    (["f1", "--e1", "35000", "--e2", "20000", "--delta-t", "0"], "--delta-t"),
    (["min-contact", "--e1", "35000", "--e2", "20000", "--width", "1e308"], "--width"),
    (["design", "--set", "paper12", "--depth-um", "1:1e308"], "depth"),
    (["bench", "--quick", "--jobs", "0"], "jobs"),
    (["export", "--table", "svm-paper", "--contact", "1,,2", "--out", "x.json"], "single commas"),
    (["min-contact", "--e1", "35000", "--e2", "20000", "--table", ""], "empty"),
    (["simulate", "--e", "400", "--out", ""], "empty"),
    (["tables", "list", "--folder", ""], "empty"),
    (["classify", "--m", "wood", "--m", "copper", "--export-c", ""], "empty"),
    (["classify", "--m", "wood", "--m", "copper", "--port", ""], "empty"),
    (["emulate", "--material", "=400"], "label"),
    (["emulate", "--material", "a\nb=400"], "label"),
    (["min-contact", "--batch", "no-such-pairs.csv"], "no such file"),
    # the cases that read a hostile file of tests/test_fuzz.py (its _files36)
    (["simulate", "--e", "400", "--sensor", "@noversion"], "designkit_sensor"),
    (["simulate", "--e", "400", "--sensor", "@dup"], "twice"),
    (["simulate", "--e", "400", "--sensor", "@e308"], "e_s"),
    (["simulate", "--e", "400", "--sensor", "@newline"], "sensor name"),
    (["min-contact", "--m1", "copper", "--m2", "glass", "--sensor", "@fast"], "samples per touch"),
    (["classify", "--m", "wood", "--m", "copper", "--port", "/dev/null", "--profile", "@empty-profile"], "empty"),
    (["calibrate", "record", "--port", "/dev/null", "--material", "w", "--out", "rec", "--profile", "@post"],
     "post_s"),
    (["sweep", "--config", "@abs"], "name"),
]
