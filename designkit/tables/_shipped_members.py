"""Digests of every array of each shipped table, as shipped (:func:`designkit.tables.store.member_digest`:
SHA-256 of the member's whole ``.npy``, header and data).

A shipped table's files are recognised by the digest of their header and zip directory, so that a question
reads only the arrays (and, for a table stored uncompressed, only the pages) it needs. The directory does
not vouch for the bytes: each array is hashed when it is first read and compared with its digest here.
Rebuilding a shipped table: regenerate this file with ``python benchmarks/rehash_tables.py --members``
(tests/test_corrupt_tables.py names a member missing from it).
"""

SHIPPED_MEMBER_DIGESTS: dict[str, dict[str, str]] = {
    'evidence-gradient-slope': {
        'chunk_wall_s': 'sha256:abc57af8c23fc6a101a094c868a37a908d5cfb57d851aba412de46d450a51569',
        'delta_down': 'sha256:456d88a5ea92c4693d5718dd5f94a70409ac1668c46edf9e19fc972b037d9e7e',
        'delta_down_hi': 'sha256:50448f74551907fb2c119644976da4a992816d695793136baa2797a089454cdf',
        'delta_down_ideal': 'sha256:8b1a16923c574960362d17acf7d0c5e705a4b6c53d85287b4d6e8eec8b63b74f',
        'delta_down_lo': 'sha256:99b443254c63cae2dd703c0269942d47b5baf4f5209f528a06606db57cb27580',
        'delta_up': 'sha256:cf594008aa7f4954add2a8b5dfb3bdbc2a2228f528827a62c6338cff0676b455',
        'delta_up_hi': 'sha256:c7b4cd24a83f6305cf30711424c9f040ba03b331ca57cf06ac4d194157bb2227',
        'delta_up_ideal': 'sha256:878610ef482126389a3e9a78e003b67477d695529cd2f9cb882ae2b5e2435e23',
        'delta_up_lo': 'sha256:e52e1dfa090b46adfa06c21a60617ffae8775e8005354408a71560011ab931e8',
        'fits': 'sha256:f9ea252abffa139faeea3fe2393edd8950c2266e4b58abffdbcd06feb0d8309e',
    },
    'f1-matrix-2s': {
        'chunk_wall_s': 'sha256:b5ea6483aff8156a27434b345672b2888b6a933d0d54d67cfa1d0e02ead44475',
        'delta_down': 'sha256:cfa978c1a3383a61a3700352880f83796e9977900033d1799487338e71c1ecef',
        'delta_down_hi': 'sha256:67eb707fe8d2292cd208902a89e9589c2c95645a00136087089e0c1ec5fd2896',
        'delta_down_ideal': 'sha256:8b1a16923c574960362d17acf7d0c5e705a4b6c53d85287b4d6e8eec8b63b74f',
        'delta_down_lo': 'sha256:cb114e3ef717615c9e2444837bbda13c9b8e57f77a3353642a315295009d0692',
        'delta_up': 'sha256:3e3b710cb53613fb4d0dbe85e6bd0675f0d31ae13f85d9b7bb6f1552b7f838f2',
        'delta_up_hi': 'sha256:a7c0adbb63cbaf4f48ba0809eb6eb7fdf6d572856657060ee04cbb625c79953f',
        'delta_up_ideal': 'sha256:878610ef482126389a3e9a78e003b67477d695529cd2f9cb882ae2b5e2435e23',
        'delta_up_lo': 'sha256:fac2feb4c543c9a8919cb9d572be6e4f9f908c2b0dfc01b209fa17a91e875b09',
        'f1_matrix': 'sha256:9a6876c3f98b3b48936c7b38b19bd1de7debca44510e23168e12648267dadc90',
        'fits': 'sha256:e2f4920e3bffa82e8b586e73be85d683e5dbf2f4bcafca4b6b0ea782f7dcf229',
    },
    'f1-matrix-fine-low': {
        'chunk_wall_s': 'sha256:2d9c7ab36e347e58c20a1ffbe7265d5fe5ad5a48cadb15b8abcdc4986e7b958e',
        'delta_down': 'sha256:c8f90a7a20c8ce83c721970510c378c0b5bf85064c2e812798ea4d2bdf62308b',
        'delta_down_hi': 'sha256:945decb66cc37a76883c4f724712ecd18201106324f26be8754696f20c9253ca',
        'delta_down_ideal': 'sha256:bca98be6b6ac67ad99d9736cafa6f35e9f21a7ca39b97da844dba0a919b3928c',
        'delta_down_lo': 'sha256:9b4927ba926ef26558fe5dbb6a83bceedb2e1798586830450b1bcdd693ff5dcc',
        'delta_up': 'sha256:9c96b1cd192bbf07d7f448d199d317cca91c70731f0320e38235703ac7650319',
        'delta_up_hi': 'sha256:556afe647e2a33784d36e5b0eabc26c7c9a1b13f731a4e34584d750f662d91d7',
        'delta_up_ideal': 'sha256:22d7e60bddbb49c90b7738c3d7892afdce7627ab5d077a1d1a1e44d6492a009b',
        'delta_up_lo': 'sha256:c72714a705c8fe747541a705a850e1f01075eb66712384fd5a17f7a2d379fe0e',
        'f1_matrix': 'sha256:1c7e41e21f12fb44662609107448f18bfce58c53e3870e593f0ec4b46c764921',
        'fits': 'sha256:83468d304a0865adf672179fefc91c3fa0f4fea40f556917cee0ce5eeadd4595',
    },
    'f1-matrix-paper': {
        'chunk_wall_s': 'sha256:6119c86394a52c5a9d6a6e3c91043d084e718a46b26f34df89516e6d7e12f8d7',
        'delta_down': 'sha256:b46a8a6731fca9eb3dc13bd682da6e8383c555061e3744e59f63729cc58b5cdc',
        'delta_down_hi': 'sha256:cadfd356482943ab5e5d2342f6732c20d1d4cab0d4902fcc0b74be4ca0ea2bdc',
        'delta_down_ideal': 'sha256:59d199b868bc1719a4bec4a609abe89733d09fd5355568682acb6dc5a94a1709',
        'delta_down_lo': 'sha256:90146d07685d8f1f1ac89cac7f2048750e4912617a8a1f87e662cb4b2c172a7c',
        'delta_up': 'sha256:819d456867f91f561a835f6fc47acaa0e3e6c7d928a834e0365d868d5c31c79c',
        'delta_up_hi': 'sha256:bf7fc41b321966c771d7f955a8dd032421a099a0ee43322cf4a0c3270d2fe56b',
        'delta_up_ideal': 'sha256:466ebdf46e457ffe7667ade959713d014beb7cf06146833738c8946cb908c212',
        'delta_up_lo': 'sha256:19ec2ba47fe40c3314d0ffc1084ffc4520495b82aa1132c442f51120b797e20f',
        'f1_matrix': 'sha256:a44ecfd886362f02b73ac6083294e9910fc3c4f17983e99ca685c82e5455952d',
        'fits': 'sha256:f353dafee275e2fda5c125d05597e8d7335c0d53f222e0f81bfca7ad982ecc09',
    },
    'ideal-paper': {
        'chunk_wall_s': 'sha256:83e64ad7340bf64d837e1955997fccc4f266798ce1512d81e666eff07a6f0895',
        'delta_down': 'sha256:b72a737dbad18e95cc371414708515ecd3be0310ea679cbd1efe72765c39ee96',
        'delta_up': 'sha256:3cd4586ada0130d7147e8f26bcffd229116e68e90812ed6bab89b1bf4cefb47e',
        'fits': 'sha256:4109b285f650b2c64ab6aa0df7a5a8601702ec8fbaadc443a40e4078d46f2161',
    },
    'svm-paper': {
        'delta_down': 'sha256:9b211367f2f04c674b9c9b0f1acf05a19ec253723220ee04a6513de6046d1203',
        'delta_down_hi': 'sha256:a2c10afb684b2068a22b279d1974440cbcb99e74bd02e26771d901f13c2c4fe5',
        'delta_down_ideal': 'sha256:d7d49b288e3db30729bfd47671551b54794a693d0c36f73df4beea162f66e365',
        'delta_down_lo': 'sha256:46ecc12e21e4b34ffb0fd6e5b32390e3d5b9ec62a66c82d9ba0d391aa1dbac63',
        'delta_up': 'sha256:ed8cf300d1aaf8995c2340f2661d752c6b5f5a692d1cb82e1316ff1c38676d0f',
        'delta_up_hi': 'sha256:e1720df1bc5a845676cd2223e8c8295e49cbf070c843d150d3c024b20c1cc91b',
        'delta_up_ideal': 'sha256:7099ffe4d7be3e6a8f17cfe72df602e2853f98d39220569d22d4a9ec3a5458d5',
        'delta_up_lo': 'sha256:7378979d0669fdce65abfae897be85d633e0565b70fc2c2dd920e53af7da71b9',
        'fits': 'sha256:5276969a60333ba0e02ea06a5adcf833437ce6abca281a1f4ff1d0d5f04eabba',
    },
    'svm-paper-varied': {
        'delta_down': 'sha256:6dcee1dea1c1b67ce5ae208a1edf9c6e154d5ecabfb94bb405f3a5224aefc16b',
        'delta_down_hi': 'sha256:d82a0e45661641075b558e80bc53beee3ae6c3d0ebb9e4c04aaaeed77bd54137',
        'delta_down_ideal': 'sha256:c370218a0cce0e837b98e1d5aca2d825507067309010fac6ad87a2482b82abc5',
        'delta_down_lo': 'sha256:bd7fc800c61cea0ce444ffe04f4ff2e809362fd6e391bca6cd482e1305587bbf',
        'delta_up': 'sha256:578c54db8c2694bbef2c0b40013d7e40112bbd2a8ddbc5b8cb6574cea8c7f645',
        'delta_up_hi': 'sha256:887577c1b8278a9609ab3fd456187d823de5dbf1d66bba131a4a2d535ae8f778',
        'delta_up_ideal': 'sha256:71e2317b6c67599198906b1a381d614ddd29bc6383918b70f522a5085bb73c84',
        'delta_up_lo': 'sha256:be670aa35ea0378f2578c5218526333d3b2a8b0c9100d6ae069423fc9cd496c7',
        'fits': 'sha256:42183517afec5a53c1de2c5e7fce9643dad18618dc6c3ba50a7e8e11167cdcfc',
    },
    'svm-fine': {
        'delta_down': 'sha256:397e469af958b8eb7523ed3306846a7d247e578bf0b426911661b079a46e2170',
        'delta_down_hi': 'sha256:d67d75b769fbb8f5659462ae184a1eb948fe4e811409cc6f22a06680bc56eb45',
        'delta_down_ideal': 'sha256:be61534d65b4bf39dfe1a12f3911ac8b90026349a841a84c0ccf8e86f3ea6984',
        'delta_down_lo': 'sha256:c3e4e623fc0a0b79dea7349601d6b1e0bd896887049abb82def2f632e8e51f06',
        'delta_up': 'sha256:997dc540e5e5153a9ba8c08cc672293ea8bbd3784984bb3ad42d1df825a979b7',
        'delta_up_hi': 'sha256:dbc4044e27b2f88d067ec2df1b4f9d6d8328a9991df87c42a2a4988ea8095609',
        'delta_up_ideal': 'sha256:ea7969df9297f348bee395b0e25e1f55e8f5c5b9f5059a1702f0a4a59e00762b',
        'delta_up_lo': 'sha256:77b840636bf30aa2cfdfd48506eb6fd48edbe32532e9127583da64d2b9647dc6',
        'fits': 'sha256:2af188ebee395b38fb8de6069d2e2d51a4c5f40f0bc436fc1b5fab5d0e16a6bc',
    },
}
