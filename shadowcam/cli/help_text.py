"""What ``shadowcam --help`` and ``shadowcam <step> --help`` say.

Offers
------
DESCRIPTION : the top-level help text, for users.
step_texts : a step's help description and example, from its module docstring.
"""

import re
import textwrap

#: what ``shadowcam --help`` says before the list of steps
DESCRIPTION = """\
Shadow cameras from a shadow that sweeps a static scene (Koppal & Narasimhan):
shadow times, dual coordinates, the dual view, outdoor arrival maps and ridge
pushbrooms. The Snakemake workflow runs these steps for every dataset
(snakemake --profile profiles/local); run one by hand to redo or inspect it.
Each step reads and writes files; `shadowcam STEP --help` lists its options,
with their units, and shows an example."""


def step_texts(doc):
    """Return ``(description, epilog)`` of a step's ``--help`` from its module docstring.

    The description is the docstring's first paragraph without its
    ````shadowcam <step>``:`` lead and without markup; the epilog is the
    literal block after the docstring's ``Example::`` line, under ``example:``.
    """
    paragraphs = doc.strip().split("\n\n")
    summary = re.sub(r"^``shadowcam [\w-]+``:\s*", "", paragraphs[0]).replace("``", "")
    description = summary[:1].upper() + summary[1:]
    starts = [k + 1 for k, text in enumerate(paragraphs) if text.strip() == "Example::"]
    if not starts:
        return description, None
    block = []
    for text in paragraphs[starts[0]:]:
        if not text.startswith(" "):
            break
        block.append(textwrap.indent(textwrap.dedent(text).strip(), "  "))
    return description, "example:\n" + "\n\n".join(block)
