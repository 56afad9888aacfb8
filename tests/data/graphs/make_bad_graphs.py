#!/usr/bin/env python3
"""Writes box_l_sorted.json and the bad graph files in bad/ from box_l.json (graph_test and cfinspect_test read
them). Each file has exactly one fault; the comment says which. Re-run after box_l.json
changes: python3 make_bad_graphs.py"""
import copy
import json
import os

HERE = os.path.dirname(os.path.abspath(__file__))
good = json.load(open(os.path.join(HERE, "box_l.json")))
good_text = open(os.path.join(HERE, "box_l.json")).read()
out = os.path.join(HERE, "bad")
os.makedirs(out, exist_ok=True)


def write(name, doc):
    with open(os.path.join(out, name), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


def variant(name, change):
    doc = copy.deepcopy(good)
    change(doc)
    write(name, doc)


# A good file with its keys sorted: readers must not depend on member order.
with open(os.path.join(HERE, "box_l_sorted.json"), "w") as f:
    json.dump(good, f, indent=1, sort_keys=True)
    f.write("\n")

# Not JSON / not a graph at all.
open(os.path.join(out, "truncated.json"), "w").write("\n".join(good_text.split("\n")[:6]))
open(os.path.join(out, "empty.json"), "w").write("")
open(os.path.join(out, "corrupt.cbor"), "wb").write(bytes([0xBF, 0x66, 0x66, 0x6F, 0x72]))
write("not_object.json", [1, 2])
variant("wrong_format.json", lambda d: d.update(format="cf-table"))
variant("wrong_version.json", lambda d: d.update(version=2))
# Structural faults.
variant("wrong_type.json", lambda d: d["cfs"][1]["pcs"][0].update(a="5"))
variant("missing_witness.json", lambda d: d["cfs"][0].pop("witness"))
variant("index_out_of_range.json", lambda d: d["cfs"][3]["pcs"][0].update(b=99))
variant("unknown_pc_type.json", lambda d: d["cfs"][0]["pcs"][0].update(type="v-v"))
variant("kind_mismatch.json", lambda d: d["cfs"][4]["pcs"][0].update(a=11))
variant("missing_cf_transition.json", lambda d: d["transitions"][2].update(to=17))
variant("bad_transition_kind.json", lambda d: d["transitions"][0].update(kind="change"))
variant("repeated_cf.json", lambda d: d["cfs"][4].update(pcs=copy.deepcopy(d["cfs"][3]["pcs"])))
variant("repeated_pc.json", lambda d: d["cfs"][2]["pcs"].__setitem__(1, copy.deepcopy(d["cfs"][2]["pcs"][0])))
variant("id_mismatch.json", lambda d: d["cfs"][1].update(id=7))
variant("not_rotation.json",
        lambda d: d["cfs"][0]["witness"].update(R=[[2.0, 0, 0], [0, 2.0, 0], [0, 0, 2.0]]))
variant("bad_model.json", lambda d: d["models"]["B"]["faces"][0]["loops"][0].__setitem__(1, -1))
variant("witness_extra_member.json", lambda d: d["cfs"][2]["witness"].update(q=[1, 0, 0, 0]))
variant("pc_count.json", lambda d: d["cfs"][2]["pcs"].extend([{"type": "v-f", "a": 1, "b": 4}, {"type": "v-f", "a": 2, "b": 4}]))
variant("missing_transitions.json", lambda d: d.pop("transitions"))
# Accepted by the reader (metadata is free-form to it), rejected by the schema: "stats"
# must be an object.
variant("schema_violation.json", lambda d: d.update(stats="none"))
# Rejected by the model schema (schemas/model.schema.json, referred to by the graph schema):
# a face's derived area must be positive; the model reader ignores derived members.
variant("model_schema_violation.json", lambda d: d["models"]["A"]["faces"][0].update(area=0))
