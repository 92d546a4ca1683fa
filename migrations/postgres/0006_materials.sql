-- Work materials (the SQLite schema's 0006, in PostgreSQL's types, with the same seed rows).
CREATE TABLE materials (
    name          TEXT             PRIMARY KEY CHECK (length(name) BETWEEN 1 AND 64),
    kc11          DOUBLE PRECISION NOT NULL CHECK (kc11 > 0),
    mc            DOUBLE PRECISION NOT NULL CHECK (mc >= 0 AND mc < 1),
    radial_ratio  DOUBLE PRECISION CHECK (radial_ratio >= 0),
    iso_group     TEXT             CHECK (iso_group IN ('P', 'M', 'K', 'N', 'S', 'H')),
    description   TEXT,
    revision      BIGINT           NOT NULL DEFAULT 1,
    created_at    TIMESTAMPTZ      NOT NULL DEFAULT now(),
    updated_at    TIMESTAMPTZ      NOT NULL DEFAULT now()
);

INSERT INTO materials (name, kc11, mc, iso_group, description) VALUES
    ('C45', 2220, 0.14, 'P', 'Unalloyed quenched-and-tempered steel C45 (1.0503). Source: König/Klocke, Fertigungsverfahren 1 (Drehen, Fräsen, Bohren): the Kienzle–Victor values for turning with carbide, widely reprinted (e.g. Tabellenbuch Metall). Typical values: the real k_c1.1 varies with tool, rake angle, wear and batch by 10–20 %; measure where the limit is tight.'),
    ('42CrMo4', 2500, 0.26, 'P', 'Low-alloy quenched-and-tempered steel 42CrMo4 (1.7225). Source: König/Klocke, Fertigungsverfahren 1 (Drehen, Fräsen, Bohren): the Kienzle–Victor values for turning with carbide, widely reprinted (e.g. Tabellenbuch Metall); VDI 3323 group 8 (Q+T, about 300 HB) gives 1725 N/mm² with m_c 0.24. Typical values: the real k_c1.1 varies with tool, rake angle, wear and batch by 10–20 %; measure where the limit is tight.'),
    ('16MnCr5', 2100, 0.26, 'P', 'Case-hardening steel 16MnCr5 (1.7131), soft. Source: König/Klocke, Fertigungsverfahren 1 (Drehen, Fräsen, Bohren): the Kienzle–Victor values for turning with carbide, widely reprinted (e.g. Tabellenbuch Metall). Typical values: the real k_c1.1 varies with tool, rake angle, wear and batch by 10–20 %; measure where the limit is tight.'),
    ('X5CrNi18-10', 2150, 0.2, 'M', 'Austenitic stainless steel X5CrNi18-10 (1.4301, AISI 304). Source: VDI 3323 material groups as tabulated in the ISCAR catalogue (Material groups according to DIN/ISO 513 and VDI 3323, k_c1 for h = 1 mm), group 14 (austenitic, about 180 HB). Typical values: the real k_c1.1 varies with tool, rake angle, wear and batch by 10–20 %; measure where the limit is tight.'),
    ('EN-GJL-250', 1150, 0.2, 'K', 'Grey cast iron EN-GJL-250 (GG-25), pearlitic. Source: VDI 3323 material groups as tabulated in the ISCAR catalogue (Material groups according to DIN/ISO 513 and VDI 3323, k_c1 for h = 1 mm), group 15 (grey cast iron, pearlitic/ferritic, about 180 HB). Typical values: the real k_c1.1 varies with tool, rake angle, wear and batch by 10–20 %; measure where the limit is tight.'),
    ('AlMg4.5Mn', 700, 0.25, 'N', 'Wrought aluminium alloy EN AW-5083 (AlMg4.5Mn0.7), not hardenable. Source: VDI 3323 material groups as tabulated in the ISCAR catalogue (Material groups according to DIN/ISO 513 and VDI 3323, k_c1 for h = 1 mm), group 21. Typical values: the real k_c1.1 varies with tool, rake angle, wear and batch by 10–20 %; measure where the limit is tight.'),
    ('AlZnMgCu1.5', 800, 0.25, 'N', 'Wrought aluminium alloy EN AW-7075 (AlZnMgCu1.5), age-hardened. Source: VDI 3323 material groups as tabulated in the ISCAR catalogue (Material groups according to DIN/ISO 513 and VDI 3323, k_c1 for h = 1 mm), group 22. Typical values: the real k_c1.1 varies with tool, rake angle, wear and batch by 10–20 %; measure where the limit is tight.'),
    ('AlSi10Mg', 700, 0.25, 'N', 'Cast aluminium alloy EN AC-43000 (AlSi10Mg), up to 12 % Si, age-hardened. Source: VDI 3323 material groups as tabulated in the ISCAR catalogue (Material groups according to DIN/ISO 513 and VDI 3323, k_c1 for h = 1 mm), group 24. Typical values: the real k_c1.1 varies with tool, rake angle, wear and batch by 10–20 %; measure where the limit is tight.'),
    ('Ti6Al4V', 2110, 0.22, 'S', 'Titanium alloy Ti6Al4V (3.7165, grade 5), alpha+beta, Rm about 1050 N/mm². Source: VDI 3323 material groups as tabulated in the ISCAR catalogue (Material groups according to DIN/ISO 513 and VDI 3323, k_c1 for h = 1 mm), group 37; other tables give less (Sandvik about 1400 N/mm²): the higher value keeps the spindle check on the safe side. Typical values: the real k_c1.1 varies with tool, rake angle, wear and batch by 10–20 %; measure where the limit is tight.');
